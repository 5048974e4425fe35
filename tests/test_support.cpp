#include "test_support.h"
#include <filesystem>
std::string testScratchDir(const std::string& name) {
    auto p = std::filesystem::temp_directory_path() / ("qsgi_test_" + name);
    std::filesystem::remove_all(p);
    std::filesystem::create_directories(p);
    return p.string();
}
