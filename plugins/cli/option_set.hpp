#pragma once
// Command-line options defined once: each option of a group is declared here with its flag, its
// help, its check and the variable it is bound to, and the same declaration both adds it to a
// CLI11 command (add_to) and writes the variable's current value back as the arguments that give
// another process the same setting (arguments: `run --processes` builds its children's command
// lines from it, so an option is never spelled twice).
#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace beaconloc::cli {

// A real number's text that reads back to the same double (17 significant digits).
std::string exact_number(double v);

class OptionSet {
 public:
  // Extra CLI11 settings of one option (->check(CLI::ExistingFile), ->expected(3), ...).
  using Configure = std::function<void(CLI::Option*)>;

  // --flag VALUE, a real number checked by `check` (number_options.hpp).
  OptionSet& real(std::string flag, double& value, std::string help, CLI::Validator check);
  // --flag VALUE, a whole number checked by `check`.
  OptionSet& whole(std::string flag, int& value, std::string help, CLI::Validator check);
  // --flag V1 .. Vcount, real numbers each checked by `check`; written back only when given.
  OptionSet& reals(std::string flag, std::vector<double>& values, int count, std::string help,
                   CLI::Validator check);
  // --flag VALUE, a whole number in [0, 2^64 - 1]; written back only when set.
  OptionSet& unsigned_number(std::string flag, std::optional<std::uint64_t>& value, std::string help);
  // --flag TEXT; written back only when not empty (empty: not given), or always (kAlways: an
  // empty text is a value, unlike the option's default).
  enum class Written { kUnlessEmpty, kAlways };
  OptionSet& text(std::string flag, std::string& value, std::string help, Configure configure = {},
                  Written written = Written::kUnlessEmpty);
  // --flag TEXT, repeatable; written back once per value.
  OptionSet& texts(std::string flag, std::vector<std::string>& values, std::string help,
                   Configure configure = {});

  // Every option of `other` too, after these.
  OptionSet& options_of(const OptionSet& other);

  // Adds every option to `app`, bound to its variable. Returns the options by flag order, for the
  // caller's constraints between them (excludes, ...).
  std::vector<CLI::Option*> add_to(CLI::App* app) const;
  // The options' current values as arguments (flag, value, ...), in declaration order.
  std::vector<std::string> arguments() const;

 private:
  struct Entry {
    std::string flag;
    std::function<CLI::Option*(CLI::App*)> add;
    std::function<void(std::vector<std::string>&)> write;
  };
  std::vector<Entry> entries_;
};

}  // namespace beaconloc::cli
