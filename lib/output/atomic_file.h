// Writes a file so that readers see either the old file or the complete new one, never a
// truncated one: data goes to a temporary file in the same folder, renamed over the final name
// by commit(). An uncommitted temporary file is removed when the object dies (error paths).
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

namespace qsgi {

class AtomicFile {
public:
    explicit AtomicFile(std::filesystem::path finalPath);
    ~AtomicFile();
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    // The temporary path, for writers that open the file themselves (e.g. OpenImageIO). It keeps
    // the final extension so format detection by name still works.
    const std::filesystem::path& temporaryPath() const { return tempPath_; }
    std::ofstream& stream();  // opened on first use, binary
    void commit();            // flush, close, rename; throws std::runtime_error on failure

private:
    std::filesystem::path finalPath_, tempPath_;
    std::ofstream stream_;
    bool committed_ = false;
};

}  // namespace qsgi
