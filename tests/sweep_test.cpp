// scripts/sweep.py end to end on a tiny grid (tests/data/sweep-tiny.json): the CSV has every
// column, error falls as photons grow, the extreme radii give no NaN or Inf, and a second
// invocation recomputes nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "test_support.h"

namespace fs = std::filesystem;

namespace {

using Row = std::map<std::string, std::string>;

// RFC 4180 fields: quoted fields may hold commas and doubled quotes.
std::vector<std::string> csvFields(const std::string& line) {
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') fields.back() += '"', ++i;
        else if (c == '"') quoted = !quoted;
        else if (c == ',' && !quoted) fields.emplace_back();
        else if (c != '\r') fields.back() += c;
    }
    return fields;
}

std::vector<Row> readCsv(const fs::path& path, std::vector<std::string>& header) {
    std::istringstream in(readFileBytes(path));
    std::string line;
    std::getline(in, line);
    header = csvFields(line);
    std::vector<Row> rows;
    while (std::getline(in, line)) {
        const std::vector<std::string> fields = csvFields(line);
        EXPECT_EQ(fields.size(), header.size()) << line;
        Row row;
        for (size_t i = 0; i < std::min(fields.size(), header.size()); ++i) row[header[i]] = fields[i];
        rows.push_back(row);
    }
    return rows;
}

std::string sweepCommand(const fs::path& out) {
    return "/usr/bin/python3 " + (sourceDir() / "scripts" / "sweep.py").string() + " " +
           (sourceDir() / "tests" / "data" / "sweep-tiny.json").string() + " --out " + out.string() +
           " --qsgi " + QSGI_CLI;
}

std::map<fs::path, fs::file_time_type> modificationTimes(const fs::path& dir) {
    std::map<fs::path, fs::file_time_type> times;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) times[e.path()] = e.last_write_time();
    return times;
}

}  // namespace

TEST(Sweep, TinyGridTabulatesFallingErrorNoNonFiniteValuesAndResumesWithoutRecomputing) {
    const fs::path out = testScratchDir("sweep-tiny");
    const CommandResult first = runCommand(sweepCommand(out));
    ASSERT_EQ(first.exitCode, 0) << first.output;
    EXPECT_NE(first.output.find("(11 computed now, 0 finished earlier)"), std::string::npos) << first.output;

    std::vector<std::string> header;
    const std::vector<Row> rows = readCsv(out / "sweep.csv", header);
    for (const char* column :
         {"family", "estimator", "photons", "radius_fraction", "radius", "k", "full_recompute", "frames", "seed",
          "rms_all", "bias_all", "rms_near_edge", "bias_near_edge", "rms_interior", "bias_interior", "noise",
          "nan_count", "inf_count", "initial_s", "median_frame_s", "threads", "jobs", "shared_cores", "other_cores", "reference"})
        EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << "no column " << column;
    // 2 photon counts x (impact count, DETP) x (incremental, --full-recompute), and 3 extremes.
    ASSERT_EQ(rows.size(), 11u);

    std::map<std::string, double> error;  // estimator @ photons -> relative RMS, incremental accuracy rows
    for (const Row& r : rows) {
        SCOPED_TRACE(r.at("estimator") + " " + r.at("photons") + " r " + r.at("radius_fraction"));
        EXPECT_EQ(r.at("nan_count"), "0");
        EXPECT_EQ(r.at("inf_count"), "0");
        // One job at a time, so no point overlaps another: a point is marked shared exactly when
        // processes outside the sweep (ctest's other tests, here) kept over a quarter core busy.
        const double other = std::stod(r.at("other_cores"));
        EXPECT_GE(other, 0.0);
        EXPECT_EQ(r.at("shared_cores"), other > 0.25 ? "True" : "False");
        EXPECT_EQ(r.at("reference"), "committed: ../reference/cornell_f0000.ply");
        if (r.at("family") == "accuracy") {
            error[r.at("estimator") + "@" + r.at("photons")] = std::stod(r.at("rms_all"));
            EXPECT_GT(std::stod(r.at("median_frame_s")), 0.0);
            EXPECT_GT(std::stod(r.at("noise")), 0.0);
        }
        if (r.at("family") == "extreme") {
            EXPECT_EQ(r.at("median_frame_s"), "");  // frame 0 alone
        }
    }
    // Noise falls as 1/sqrt(photons): 10x the photons gives ~0.32x the error, plus the
    // reference's own ~1 % noise and the estimator's bias, which do not fall. Half is a margin of
    // more than a factor 1.5 over that expectation.
    for (const char* estimator : {"impact-count", "detp:clip"}) {
        SCOPED_TRACE(estimator);
        const double few = error.at(std::string(estimator) + "@1000"), many = error.at(std::string(estimator) + "@10000");
        EXPECT_LT(many, 0.5 * few) << "error " << few << " at 1e3 photons, " << many << " at 1e4";
    }
    for (const char* plot : {"error_vs_photons.png", "pareto.png", "time_vs_photons.png", "bias_vs_radius.png",
                             "extremes.png"})
        EXPECT_TRUE(fs::file_size(out / plot) > 10000) << plot;

    // Again: every point is found finished; no render, compare or result is redone.
    const auto before = modificationTimes(out / "points");
    const CommandResult second = runCommand(sweepCommand(out));
    ASSERT_EQ(second.exitCode, 0) << second.output;
    EXPECT_NE(second.output.find("(0 computed now, 11 finished earlier)"), std::string::npos) << second.output;
    EXPECT_EQ(modificationTimes(out / "points"), before);
}

TEST(Sweep, BadConfigIsOneMessageNamingTheKeyAndExitTwo) {
    const fs::path dir = testScratchDir("sweep-bad");
    const fs::path config = dir / "bad.json";
    std::ofstream(config) << R"({"scene": ")" << (sourceDir() / "data" / "cornell" / "cornell.gltf").string()
                          << R"(", "grid": {"photons": [1000], "radius_fraction": [2.0], "estimators": ["detp"]}})";
    const CommandResult r = runCommand("/usr/bin/python3 " + (sourceDir() / "scripts" / "sweep.py").string() + " " +
                                       config.string() + " --out " + (dir / "out").string());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("grid.radius_fraction[0]"), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out"));
}
