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
    // Flush, close, fsync, rename, fsync the folder: after commit() returns, the file survives a
    // crash or power loss under its final name. Throws std::runtime_error on failure.
    void commit();

    // Removes the temporary files a killed process left in `folder` (names made by this class).
    static void removeStaleTemporaries(const std::filesystem::path& folder);

private:
    std::filesystem::path finalPath_, tempPath_;
    std::ofstream stream_;
    bool committed_ = false;
};

}  // namespace qsgi
