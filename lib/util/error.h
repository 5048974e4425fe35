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

// Non-fatal findings while reading inputs, reported once each by the caller.
struct Warnings {
    std::vector<std::string> messages;
    void add(std::string message) {
        for (const auto& m : messages)
            if (m == message) return;
        messages.push_back(std::move(message));
    }
};

}  // namespace qsgi
