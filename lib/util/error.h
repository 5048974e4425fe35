// Errors a user can act on. An InputError names the file, the place in it and the problem; the
// CLI turns it into one line on stderr and exit code 2 (docs/design.md §8).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace qsgi {

class InputError : public std::runtime_error {
public:
    // file: the user's file (or option name), place: where in it ("nodes[3].matrix", "frame 12"),
    // problem: what is wrong, in words the user can act on.
    InputError(std::string file, std::string place, std::string problem)
        : std::runtime_error(format(file, place, problem)),
          file_(std::move(file)), place_(std::move(place)), problem_(std::move(problem)) {}

    const std::string& file() const { return file_; }
    const std::string& place() const { return place_; }
    const std::string& problem() const { return problem_; }

private:
    static std::string format(const std::string& file, const std::string& place, const std::string& problem) {
        std::string out = file;
        if (!place.empty()) out += (out.empty() ? "" : ": ") + place;
        return out + (out.empty() ? "" : ": ") + problem;
    }
    std::string file_, place_, problem_;
};

// The machine, not the input, stopped the run: a full disk, an I/O error, a read-only file system.
// `folder` is where it happened; the CLI prints the message and exits 74 (sysexits' EX_IOERR), so
// a batch system can tell "free space and --resume" from "fix the input" (docs/design.md §8).
class EnvironmentError : public std::runtime_error {
public:
    EnvironmentError(std::string folder, std::string problem)
        : std::runtime_error(folder + ": " + problem), folder_(std::move(folder)), problem_(std::move(problem)) {}
    const std::string& folder() const { return folder_; }
    const std::string& problem() const { return problem_; }

private:
    std::string folder_, problem_;
};

// Another run holds the output folder's lock: the CLI prints the message (the folder and the
// holder) and exits 75 (sysexits' EX_TEMPFAIL: try again later).
class FolderBusyError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Non-fatal findings while reading inputs, reported once each by the caller.
struct Warnings {
    std::vector<std::string> messages;
    void add(std::string message) {
        for (const auto& m : messages)
            if (m == message) return;
        messages.push_back(std::move(message));
    }
};

// A library's message (OpenImageIO's may span lines) made one line, as every message qsgi prints is.
inline std::string oneLine(std::string text) {
    for (char& c : text)
        if (c == '\n') c = ' ';
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text;
}

}  // namespace qsgi
