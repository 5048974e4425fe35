// The option table (lib/pipeline/render_options.cpp) against everything made from it or meant to
// agree with it: the docs' table, --help, RenderSettings' defaults, the resume fingerprint, the
// timing log, the config reader's and the command line's checks, and the sweep script's copy of
// the default radius.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <fstream>
#include <cctype>
#include <optional>
#include <set>

#include "pipeline/render_options.h"
#include "pipeline/render_settings.h"
#include "pipeline/run_fingerprint.h"
#include "test_support.h"
#include "util/error.h"
#include "util/field_count.h"
#include "util/nearest_name.h"

using namespace qsgi;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The InputError `work` throws (one naming nothing if it throws none).
template <class Work>
InputError refusal(Work&& work) {
    try {
        work();
    } catch (const InputError& e) {
        return e;
    }
    return InputError("", "", "");
}

// A value of the option's type other than the one in force in `s` (null if the test has none).
json otherValue(const RenderOption& o, const RenderSettings& s) {
    const json now = o.get(s);
    switch (o.type) {
        case OptionType::Integer: {
            const int64_t v = now.is_null() ? int64_t(o.min) : now.get<int64_t>();
            return v + 1 <= int64_t(std::min(o.max, 9.0e18)) ? v + 1 : v - 1;
        }
        case OptionType::Number: return now.is_null() ? 0.5 : now.get<double>() / 2;
        case OptionType::Boolean: return !now.get<bool>();
        case OptionType::Choice:
            if (now.is_null()) return o.choices.back();  // the first is the default
            for (const std::string& c : o.choices)
                if (c != now) return c;
            return nullptr;
        case OptionType::Text:
            if (std::string(o.key) == "frames") return "0:3";
            if (std::string(o.key) == "animation") return "gltf:1";
            return "elsewhere.gltf";
        case OptionType::Object:
            if (std::string(o.key) == "camera") return 3;
            if (std::string(o.key) == "sky") return json::array({0.5, 0.25, 1});
            if (std::string(o.key) == "environment") return "sky.exr";
            if (std::string(o.key) == "gather_cache") return now == json(0.5) ? json(0.25) : json(0.5);
            return json::parse(R"([{"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1]}])");
    }
    return nullptr;
}

}  // namespace

TEST(RenderOptions, TheDocsTableIsTheDeclaredOptions) {
    const std::string docs = readFileBytes(sourceDir() / "docs" / "command-line.md");
    const std::string begin = "<!-- options: the output of `qsgi options --markdown` -->\n", end = "<!-- end of options -->";
    const size_t from = docs.find(begin), to = docs.find(end);
    ASSERT_NE(from, std::string::npos) << "docs/command-line.md has lost its options table's opening marker";
    ASSERT_NE(to, std::string::npos) << "docs/command-line.md has lost its options table's closing marker";
    EXPECT_EQ(docs.substr(from + begin.size(), to - from - begin.size()), optionsMarkdownTable())
        << "docs/command-line.md's option table differs from the declared options: paste the output of "
           "`build/cli/qsgi options --markdown` between the markers";
}

TEST(RenderOptions, HelpListsEveryFlagWithItsHelpAndNothingElse) {
    const CommandResult help = runQsgi("render --help");
    ASSERT_EQ(help.exitCode, 0) << help.output;
    std::set<std::string> declared = {"--help"};
    for (const RenderOption& o : renderOptions()) {
        if (!o.flag) continue;
        declared.insert(o.flag);
        SCOPED_TRACE(o.flag);
        EXPECT_NE(help.output.find(std::string(o.flag) + " "), std::string::npos);
        EXPECT_NE(help.output.find(std::string(o.help).substr(0, 40)), std::string::npos);
    }
    // Every word "--x…" of --help (a flag: "--" then a lowercase letter, then letters and '-').
    // Scanned by hand: GCC 12 warns inside <regex> under the sanitized build's -O1.
    const std::string& text = help.output;
    for (size_t at = text.find("--"); at != std::string::npos; at = text.find("--", at + 2)) {
        if (at + 2 >= text.size() || !std::islower(static_cast<unsigned char>(text[at + 2]))) continue;
        if (at > 0 && text[at - 1] == '-') continue;  // inside a longer run of dashes
        size_t end = at + 2;
        while (end < text.size() && (std::islower(static_cast<unsigned char>(text[end])) || text[end] == '-')) ++end;
        const std::string word = text.substr(at, end - at);
        EXPECT_TRUE(declared.count(word) || text.find("(default: " + word) != std::string::npos || word == "--config")
            << word << " is in --help but not among the declared options";
        at = end - 2;
    }
}

// A default the docs state is the value RenderSettings starts with.
TEST(RenderOptions, EveryStatedDefaultIsTheSettingsDefault) {
    const RenderSettings fresh;
    const json before = optionValues(fresh, OptionSelection::All);
    int checked = 0;
    for (const RenderOption& o : renderOptions()) {
        if (!o.key || !o.set) continue;
        json value;
        const std::string text = o.defaultText;
        if (o.type == OptionType::Boolean) value = text == "true";
        else if (o.type == OptionType::Choice) value = text;
        else if (o.type == OptionType::Integer || o.type == OptionType::Number) value = json::parse(text, nullptr, false);
        else continue;  // text, objects and descriptive defaults ("1.5 % of …") have no value to apply
        if (value.is_discarded()) continue;
        SCOPED_TRACE(o.key);
        RenderSettings s = fresh;
        applyOption(o, value, {"test", o.key, {}}, s);
        EXPECT_EQ(optionValues(s, OptionSelection::All), before);
        ++checked;
    }
    EXPECT_GE(checked, 24);
    // The one descriptive default that is a number in the code.
    const RenderOption* radius = optionWithKey("radius");
    ASSERT_NE(radius, nullptr);
    EXPECT_EQ(std::string(radius->defaultText).rfind(std::to_string(kDefaultRadiusFraction * 100).substr(0, 3) + " %", 0), 0u)
        << radius->defaultText;
}

// Exactly the options marked as fingerprinted change the fingerprint; an option that means
// nothing for a run (k under DETP) changes nothing.
TEST(RenderOptions, ExactlyTheFingerprintedOptionsChangeTheFingerprint) {
    const Scene scene;
    const Camera camera;
    std::set<std::string> seenChanging;
    for (EstimatorKind kind : {EstimatorKind::PhotonMap, EstimatorKind::Detp}) {
        RenderSettings base;
        base.scenePath = "scene.gltf";
        base.estimator.kind = kind;
        const std::string reference = runFingerprint(base, scene, "", camera).digest;
        for (const RenderOption& o : renderOptions()) {
            if (!o.key || !o.set) continue;
            // A level sets other options, which are fingerprinted (QualityLevel.ALevelAndItsValues…).
            if (std::string(o.key) == "quality") continue;
            SCOPED_TRACE(std::string(o.key) + " with " + estimatorName(kind));
            const json other = otherValue(o, base);
            ASSERT_FALSE(other.is_null());
            RenderSettings changed = base;
            applyOption(o, other, {"test", o.key, {}}, changed);
            const bool meaningful = !o.get(changed).is_null() || !o.get(base).is_null();
            if (meaningful) {
                ASSERT_NE(o.get(changed), o.get(base));
            }
            const bool differs = runFingerprint(changed, scene, "", camera).digest != reference;
            if (o.fingerprinted && meaningful) {
                EXPECT_TRUE(differs);
                seenChanging.insert(o.key);
            } else if (!o.fingerprinted) {
                EXPECT_FALSE(differs);
            }
        }
        // k means nothing to DETP: a folder made with another k may be resumed.
        if (kind == EstimatorKind::Detp) {
            RenderSettings otherK = base;
            otherK.estimator.photonMap.k = 7;
            EXPECT_EQ(runFingerprint(otherK, scene, "", camera).digest, reference);
        }
    }
    for (const RenderOption& o : renderOptions()) {
        if (o.key && o.fingerprinted) {
            EXPECT_TRUE(seenChanging.count(o.key)) << o.key << " was never seen to change the fingerprint";
        }
    }
}

TEST(RenderOptions, TheTimingLogRecordsExactlyTheLoggedOptionsAsTheRunHadThem) {
    const fs::path out = fs::path(testScratchDir("options-log")) / "out";
    fs::remove_all(out);
    const std::string scene = (sourceDir() / "data" / "cornell" / "cornell.gltf").string();
    const CommandResult r = runQsgi("render " + scene + " --estimator photon-map --k 9 --photons 3000 --seed 5 --frames 0:0 "
                                    "--width 8 --height 6 --no-exr --threads 1 --quiet --out " + out.string());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const json config = json::parse(readFileBytes(out / "timing.json")).at("config");
    std::set<std::string> expected = {"inputs_fingerprint"}, found;
    for (const RenderOption& o : renderOptions())
        if (o.key && o.logged) expected.insert(o.key);
    for (auto it = config.begin(); it != config.end(); ++it) found.insert(it.key());
    EXPECT_EQ(found, expected);
    EXPECT_EQ(config.at("estimator"), "photon-map");
    EXPECT_EQ(config.at("k"), 9);
    EXPECT_EQ(config.at("photons"), 3000);
    EXPECT_EQ(config.at("seed"), 5);
    EXPECT_EQ(config.at("threads"), 1);
    EXPECT_TRUE(config.at("detp_index").is_null()) << "DETP's index means nothing to the photon map";
}

// A value is checked by the same rule whether a config or the command line gives it: the same
// settings from a good value, the same words (after the source and place) for a bad one.
TEST(RenderOptions, ConfigAndCommandLineApplyTheSameRules) {
    int compared = 0;
    for (const RenderOption& o : renderOptions()) {
        if (!o.key || !o.flag || !o.set || o.type == OptionType::Boolean) continue;
        SCOPED_TRACE(o.key);
        RenderSettings base;
        base.estimator.kind = EstimatorKind::PhotonMap;  // so that radius and k are in force
        const json good = otherValue(o, base);
        RenderSettings fromConfig = base, fromCommandLine = base;
        applyOption(o, good, {"config.json", o.key, {}}, fromConfig);
        applyCommandLineOption(o, good.is_string() ? good.get<std::string>() : good.dump(), fromCommandLine);
        EXPECT_EQ(optionValues(fromConfig, OptionSelection::All), optionValues(fromCommandLine, OptionSelection::All));
        std::vector<json> bad = {"nonsense"};
        if (o.type == OptionType::Integer) bad = {o.min - 1, 1e20, 2.5, "many"};
        if (o.type == OptionType::Number) bad = {0, -1, 1e300, "fast"};
        if (o.type == OptionType::Text || o.type == OptionType::Object) bad = {};
        if (std::string(o.key) == "gather_cache") bad = {"nonsense", -0.5, 2, 1e300};
        for (const json& value : bad) {
            SCOPED_TRACE(value.dump());
            RenderSettings a = base, b = base;
            const InputError viaConfig = refusal([&] { applyOption(o, value, {"config.json", o.key, {}}, a); });
            const InputError viaCommandLine =
                refusal([&] { applyCommandLineOption(o, value.is_string() ? value.get<std::string>() : value.dump(), b); });
            EXPECT_EQ(viaConfig.file(), "config.json");
            EXPECT_EQ(viaConfig.place(), o.key);
            EXPECT_EQ(viaCommandLine.file(), "command line");
            EXPECT_EQ(viaCommandLine.place(), o.flag);
            EXPECT_FALSE(viaConfig.problem().empty());
            EXPECT_EQ(viaConfig.problem(), viaCommandLine.problem());
            ++compared;
        }
    }
    EXPECT_GE(compared, 40);
}

// Out-of-range values name the range, not the type (1e20 photons is an integer, too many).
TEST(RenderOptions, OutOfRangeValuesSayTheRangeAndNameTheirSource) {
    RenderSettings s;
    const InputError photons = refusal([&] { applyOption(*optionWithKey("photons"), 1e20, {"c.json", "photons", {}}, s); });
    EXPECT_EQ(photons.problem().rfind("1e+20 is outside 1..4294967296", 0), 0u) << photons.what();
    const InputError radius = refusal([&] { applyOption(*optionWithKey("radius"), 1e300, {"c.json", "radius", {}}, s); });
    EXPECT_EQ(std::string(radius.what()).rfind("c.json: radius: 1e+300", 0), 0u) << radius.what();
}

// scripts/qsgibatch/grid.py computes sweep radii with qsgi's default fraction: the same number.
TEST(RenderOptions, TheSweepScriptsDefaultRadiusFractionIsQsgis) {
    std::ifstream grid(sourceDir() / "scripts" / "qsgibatch" / "grid.py");
    std::string line;
    const std::string prefix = "DEFAULT_RADIUS_FRACTION = ";
    bool found = false;
    while (std::getline(grid, line))
        if (line.rfind(prefix, 0) == 0) {
            EXPECT_FLOAT_EQ(std::stof(line.substr(prefix.size())), kDefaultRadiusFraction);
            found = true;
        }
    EXPECT_TRUE(found) << "grid.py no longer states DEFAULT_RADIUS_FRACTION";
}

namespace {
struct ThreeFields {
    int a = 0;
    std::optional<double> b;
    std::vector<std::string> c;
};
struct Nested {
    ThreeFields inner;
    bool d = false;
};
}  // namespace

// Every setting is reachable: render_options.cpp asserts RenderSettings' field count beside the
// table, so a field added without an option fails the build. The count it rests on is exact,
// for the kinds of field RenderSettings holds (optionals, vectors, nested aggregates).
TEST(RenderOptions, EverySettingIsReachableAndTheFieldCountItRestsOnIsExact) {
    static_assert(qsgi::fieldCount<ThreeFields>() == 3);
    static_assert(qsgi::fieldCount<Nested>() == 2);
    // --no-aim and aim_emission, the setting an option had lost, set it again, and it reaches the
    // fingerprint (aimed and unaimed photons differ).
    const RenderOption* aim = optionWithKey("aim_emission");
    ASSERT_NE(aim, nullptr);
    ASSERT_NE(aim->flag, nullptr);
    EXPECT_EQ(std::string(aim->flag), "--no-aim");
    RenderSettings fromFlag, fromConfig;
    applyCommandLineOption(*aim, "", fromFlag);
    applyOption(*aim, false, {"test", "aim_emission", {}}, fromConfig);
    EXPECT_FALSE(fromFlag.trace.aim.enabled);
    EXPECT_FALSE(fromConfig.trace.aim.enabled);
    EXPECT_TRUE(RenderSettings().trace.aim.enabled);
    EXPECT_TRUE(aim->fingerprinted);
    const CommandResult r = runQsgi("render " + (sourceDir() / "data/cornell/cornell.gltf").string() +
                                    " --no-aim --photons 2000 --no-exr --quiet --out " +
                                    (fs::path(testScratchDir("no-aim")) / "out").string());
    EXPECT_EQ(r.exitCode, 0) << r.output;
}

// An unknown config key names the nearest known key, whether it is misspelt or put in other
// words (docs/command-line.md: "names the nearest known key"); a word that shares nothing with
// any key gets no guess.
TEST(RenderOptions, AnUnknownKeyNamesTheNearestKnownKeyMisspeltOrInOtherWords) {
    std::vector<std::string> keys;
    for (const RenderOption& o : renderOptions())
        if (o.key) keys.push_back(o.key);
    const std::vector<std::pair<std::string, std::string>> typos = {
        {"photon", "photons"},          {"photon_count", "photons"},   {"num_photons", "photons"},
        {"photonCount", "photons"},     {"totalphotons", "photons"},   {"num_threads", "threads"},
        {"thread_count", "threads"},    {"maxBounces", "max_bounces"}, {"max_bounce", "max_bounces"},
        {"bounces_max", "max_bounces"}, {"image_width", "width"},      {"output_dir", "out"},
        {"outdir", "out"},              {"exr-half", "exr_half"},      {"seed_value", "seed"},
        {"estimater", "estimator"},     {"gltf_output", "gltf_out"},   {"detp_boundry", "detp_boundary"}};
    for (const auto& [typo, key] : typos)
        EXPECT_EQ(didYouMean(typo, keys), " (did you mean \"" + key + "\"?)") << typo;
    for (const char* unrelated : {"resolution", "vignette", "tone_curve"}) EXPECT_EQ(didYouMean(unrelated, keys), "") << unrelated;
    // The same rule for flags, choices and node names.
    EXPECT_EQ(didYouMean("--photon-count", {"--photons", "--out", "--threads"}), " (did you mean \"--photons\"?)");
    EXPECT_EQ(didYouMean("photon_mapping", {"impact-count", "photon-map", "detp"}), " (did you mean \"photon-map\"?)");
    EXPECT_EQ(didYouMean("Floor_2", {"Lamp", "Floor"}), " (did you mean \"Floor\"?)");

    RenderSettings s;
    const InputError e = refusal([&] { applyConfigJson("my.json", json{{"photon_count", 1000}}, s); });
    EXPECT_EQ(std::string(e.what()), "my.json: photon_count: unknown key (did you mean \"photons\"?)");
}

// A config's lights take KHR_lights_punctual's spot light and at most one sky or environment map;
// --sky and --environment set the same settings from the command line, by the same rules.
TEST(RenderOptions, LightsTakeSpotsAndOneSkyOrEnvironment) {
    RenderSettings s;
    applyConfigJson("c.json", json::parse(R"({"lights": [
        {"type": "spot", "position": [0, 2, 0], "direction": [0, -2, 0], "intensity": [5, 5, 5], "outer_cone_angle": 0.6},
        {"type": "sky", "radiance": [0.25, 0.5, 1]}]})"), s);
    ASSERT_EQ(s.extraLights.size(), 1u);
    EXPECT_EQ(s.extraLights[0].type, LightType::Spot);
    EXPECT_FLOAT_EQ(s.extraLights[0].cosOuterCone, std::cos(0.6f));
    EXPECT_EQ(s.extraLights[0].direction, Vec3f(0, -1, 0));
    ASSERT_TRUE(s.environment.sky.has_value());
    EXPECT_EQ(*s.environment.sky, Vec3f(0.25f, 0.5f, 1.0f));

    // The command line's --sky R,G,B is the config's [r, g, b]; a later --environment replaces it.
    const RenderOption* sky = optionWithKey("sky");
    const RenderOption* environment = optionWithKey("environment");
    ASSERT_TRUE(sky && environment);
    RenderSettings t;
    applyCommandLineOption(*sky, "0.25,0.5,1", t);
    EXPECT_EQ(sky->get(t), sky->get(s));
    applyCommandLineOption(*sky, "2", t);
    EXPECT_EQ(*t.environment.sky, Vec3f(2.0f));
    applyCommandLineOption(*environment, R"({"image": "maps/sky.exr", "rotation": 90, "intensity": 3})", t);
    EXPECT_FALSE(t.environment.sky.has_value());
    EXPECT_EQ(t.environment.image, "maps/sky.exr");
    EXPECT_EQ(t.environment.rotationDegrees, 90.0f);
    EXPECT_EQ(t.environment.intensity, 3.0f);
    applyCommandLineOption(*environment, "other.hdr", t);
    EXPECT_EQ(t.environment.image, "other.hdr");
    EXPECT_EQ(t.environment.rotationDegrees, 0.0f);

    auto refusedFor = [](const std::string& config) {
        RenderSettings r;
        return refusal([&] { applyConfigJson("c.json", json::parse(config), r); });
    };
    EXPECT_EQ(refusedFor(R"({"lights": [{"type": "sky", "radiance": 1}, {"type": "environment", "image": "a.exr"}]})").place(),
              "lights[1]");
    EXPECT_EQ(refusedFor(R"({"lights": [{"type": "sky", "radiance": [1, -1, 1]}]})").place(), "lights[0].radiance");
    EXPECT_EQ(refusedFor(R"({"lights": [{"type": "spot", "position": [0, 0, 0], "direction": [0, -1, 0],
                                          "intensity": [1, 1, 1], "outer_cone_angle": 0.3, "inner_cone_angle": 0.4}]})").place(),
              "lights[0].inner_cone_angle");
    EXPECT_EQ(refusedFor(R"({"environment": {"image": "a.exr", "intensity": 0}})").place(), "environment.intensity");
    EXPECT_EQ(refusedFor(R"({"lights": [{"type": "area"}]})").place(), "lights[0].type");
    RenderSettings r;
    EXPECT_EQ(refusal([&] { applyCommandLineOption(*sky, "1,x,2", r); }).place(), "--sky");
    EXPECT_EQ(refusal([&] { applyCommandLineOption(*sky, "-1", r); }).place(), "--sky");
}
