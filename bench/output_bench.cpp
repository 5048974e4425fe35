// What verifying frames costs (issue 32): XXH3 over a frame's bytes as they are written, and
// re-reading and checksumming a frame's files as --resume does (from the page cache, as right
// after a run, and the lower bound of a cold disk's time), beside writing the same files (each
// fsynced), in the same run. Sizes are data/cornell's at the default 640×480: a 1.39 MB PLY and a
// 2.25 MB EXR. Run: scripts/bench.sh --benchmark_filter='Checksum|Verify|WriteFrame'.
#include <benchmark/benchmark.h>

#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "output/file_checksum.h"
#include "output/output_directory.h"

using namespace qsgi;

namespace {

std::string noise(size_t bytes) {
    std::mt19937_64 random(11);
    std::string text(bytes, '\0');
    for (size_t i = 0; i + 8 <= bytes; i += 8) {
        const uint64_t v = random();
        std::memcpy(&text[i], &v, 8);
    }
    return text;
}

const std::vector<std::string>& frameFiles() {
    static const std::vector<std::string> files = {noise(1387100), noise(2246118)};
    return files;
}

int64_t frameBytes() {
    int64_t total = 0;
    for (const std::string& f : frameFiles()) total += int64_t(f.size());
    return total;
}

std::filesystem::path scratch() {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "qsgi_bench_output";
    std::filesystem::create_directories(dir);
    return dir;
}

void ChecksumAtWrite(benchmark::State& state) {
    for (auto _ : state)
        for (const std::string& f : frameFiles()) benchmark::DoNotOptimize(xxh3Hex(f));
    state.SetBytesProcessed(state.iterations() * frameBytes());
}
BENCHMARK(ChecksumAtWrite)->Unit(benchmark::kMillisecond);

void VerifyFrameAtResume(benchmark::State& state) {
    OutputDirectory folder(scratch());
    std::vector<FileRecord> records;
    for (size_t i = 0; i < frameFiles().size(); ++i)
        records.push_back(folder.write("frame_0000." + std::to_string(i), frameFiles()[i]));
    for (auto _ : state)
        for (const FileRecord& r : records)
            if (fileMismatch(folder.fd(), r, "bench")) state.SkipWithError("a frame file failed verification");
    state.SetBytesProcessed(state.iterations() * frameBytes());
}
BENCHMARK(VerifyFrameAtResume)->Unit(benchmark::kMillisecond);

void WriteFrameFiles(benchmark::State& state) {
    OutputDirectory folder(scratch());
    for (auto _ : state)
        for (size_t i = 0; i < frameFiles().size(); ++i)
            benchmark::DoNotOptimize(folder.write("frame_0001." + std::to_string(i), frameFiles()[i]));
    state.SetBytesProcessed(state.iterations() * frameBytes());
}
BENCHMARK(WriteFrameFiles)->Unit(benchmark::kMillisecond);

}  // namespace
