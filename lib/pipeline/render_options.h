// Every option of a render, declared once: its config key, its command-line flag, its type and
// range, its default, its help, and whether it reaches the resume fingerprint and timing.json.
// The config reader (applyConfigJson below), the command line (cli/main.cpp), validateSettings, the
// fingerprint (run_fingerprint.cpp), the timing log's "config" and the option table of
// docs/command-line.md are all made from this list (tests/render_options_test.cpp checks the docs
// and --help against it). Adding an option is one entry here and one field in RenderSettings or in a
// stage's settings it holds (trace_settings.h, estimator_settings.h, ...), which the entry sets directly.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/render_settings.h"

namespace qsgi {

enum class OptionType {
    Integer,  // an integer in [min, max] (a config may write 1e6)
    Number,   // a finite number in (min, max]
    Boolean,  // true or false in a config; on the command line a flag that sets `flagSets`
    Choice,   // one of `choices`
    Text,     // a string: a path, a frame range, an animation selector
    Object,   // config only, structured (lights; camera takes an index or an object)
};

// Where a value came from, for messages and for resolving relative paths.
struct OptionSource {
    std::string file;                 // a config's path, or "command line"
    std::string place;                // the key or the flag, as the user wrote it
    std::filesystem::path base;       // relative paths in a config are relative to its folder
};

struct RenderOption {
    const char* key;   // config key; nullptr: command line only
    const char* flag;  // command-line flag ("--photons"); nullptr: config only
    OptionType type;
    double min = 0, max = 0;         // Integer: inclusive; Number: above min, at most max
    const char* rangeNote = "";      // why the range is what it is, appended to a refusal
    std::vector<std::string> choices;
    bool flagSets = true;            // Boolean: the value the flag sets (--no-aim sets aim_emission false)
    const char* metavar = "";        // the flag's argument in the docs ("N", "A:B")
    const char* defaultText = "";    // as the docs and --help show it
    const char* help = "";
    bool fingerprinted = false;      // reaches the frame files: --resume refuses a folder made with another value
    bool logged = false;             // recorded in timing.json's "config"
    // Stores a value that has passed its type and range check (in its JSON form) into the settings.
    void (*set)(RenderSettings&, const nlohmann::json& value, const OptionSource& source) = nullptr;
    // The value in force, in the same JSON form; null where it is unset or means nothing for this
    // run (k without the photon map, qmc_bounces under random).
    nlohmann::json (*get)(const RenderSettings&) = nullptr;
};

// The list, in the order the docs and --help show it.
const std::vector<RenderOption>& renderOptions();
// The option with this config key, or nullptr.
const RenderOption* optionWithKey(const std::string& key);

// Checks `value` against the option's type and range and stores it. Throws InputError naming
// source.file and source.place.
void applyOption(const RenderOption& option, const nlohmann::json& value, const OptionSource& source,
                 RenderSettings& settings);
// The same for a command-line argument: its text becomes the JSON value a config would hold
// ("1e6" a number, "detp" a string) and is checked by the same rules.
void applyCommandLineOption(const RenderOption& option, const std::string& text, RenderSettings& settings);

// Reads a config file into `settings` (only the keys present change). Relative scene and
// animation paths are resolved against the config's folder. Throws InputError.
void applyConfigFile(const std::string& path, RenderSettings& settings);
// The same for a config already parsed (`path` names it in messages and resolves relative paths).
void applyConfigJson(const std::string& path, const nlohmann::json& doc, RenderSettings& settings);

// Checks every option's value by the rules its declaration gives (for settings filled by a
// program), and what no single option can: a scene is given, K is at most max_bounces.
void validateSettings(const RenderSettings& settings);

// Every option's value in force, by config key (options without a key are left out); only those
// that reach the frame files, or only those timing.json records, when asked. Those two are for
// recording: a text that is not UTF-8 (a path) is given as pathJson gives it.
enum class OptionSelection { All, Fingerprinted, Logged };
nlohmann::json optionValues(const RenderSettings& settings, OptionSelection selection);

// The table of docs/command-line.md (Markdown), made from the list.
std::string optionsMarkdownTable();
// The list as JSON (`qsgi options`): for scripts that need a default or a range.
nlohmann::json optionsDescription();

}  // namespace qsgi
