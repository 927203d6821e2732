#include "option_set.hpp"

#include <iomanip>
#include <sstream>

#include "number_options.hpp"

namespace beaconloc::cli {

std::string exact_number(double v) {
  std::ostringstream s;
  s << std::setprecision(17) << v;
  return s.str();
}

OptionSet& OptionSet::real(std::string flag, double& value, std::string help, CLI::Validator check) {
  entries_.push_back({flag,
                      [flag, &value, help, check](CLI::App* app) {
                        return app->add_option(flag, value, help)->transform(check);
                      },
                      [flag, &value](std::vector<std::string>& out) {
                        out.push_back(flag);
                        out.push_back(exact_number(value));
                      }});
  return *this;
}

OptionSet& OptionSet::whole(std::string flag, int& value, std::string help, CLI::Validator check) {
  entries_.push_back({flag,
                      [flag, &value, help, check](CLI::App* app) {
                        return app->add_option(flag, value, help)->transform(check);
                      },
                      [flag, &value](std::vector<std::string>& out) {
                        out.push_back(flag);
                        out.push_back(std::to_string(value));
                      }});
  return *this;
}

OptionSet& OptionSet::reals(std::string flag, std::vector<double>& values, int count, std::string help,
                            CLI::Validator check) {
  entries_.push_back({flag,
                      [flag, &values, count, help, check](CLI::App* app) {
                        return app->add_option(flag, values, help)->expected(count)->transform(check);
                      },
                      [flag, &values](std::vector<std::string>& out) {
                        if (values.empty()) return;
                        out.push_back(flag);
                        for (double v : values) out.push_back(exact_number(v));
                      }});
  return *this;
}

OptionSet& OptionSet::unsigned_number(std::string flag, std::optional<std::uint64_t>& value, std::string help) {
  entries_.push_back({flag,
                      [flag, &value, help](CLI::App* app) {
                        return app->add_option(flag, value, help)->transform(any_unsigned());
                      },
                      [flag, &value](std::vector<std::string>& out) {
                        if (!value) return;
                        out.push_back(flag);
                        out.push_back(std::to_string(*value));
                      }});
  return *this;
}

OptionSet& OptionSet::text(std::string flag, std::string& value, std::string help, Configure configure,
                           Written written) {
  entries_.push_back({flag,
                      [flag, &value, help, configure](CLI::App* app) {
                        CLI::Option* option = app->add_option(flag, value, help);
                        if (configure) configure(option);
                        return option;
                      },
                      [flag, &value, written](std::vector<std::string>& out) {
                        if (value.empty() && written == Written::kUnlessEmpty) return;
                        out.push_back(flag);
                        out.push_back(value);
                      }});
  return *this;
}

OptionSet& OptionSet::texts(std::string flag, std::vector<std::string>& values, std::string help,
                            Configure configure) {
  entries_.push_back({flag,
                      [flag, &values, help, configure](CLI::App* app) {
                        CLI::Option* option = app->add_option(flag, values, help);
                        if (configure) configure(option);
                        return option;
                      },
                      [flag, &values](std::vector<std::string>& out) {
                        for (const std::string& v : values) {
                          out.push_back(flag);
                          out.push_back(v);
                        }
                      }});
  return *this;
}

OptionSet& OptionSet::options_of(const OptionSet& other) {
  entries_.insert(entries_.end(), other.entries_.begin(), other.entries_.end());
  return *this;
}

std::vector<CLI::Option*> OptionSet::add_to(CLI::App* app) const {
  std::vector<CLI::Option*> options;
  options.reserve(entries_.size());
  for (const Entry& e : entries_) options.push_back(e.add(app));
  return options;
}

std::vector<std::string> OptionSet::arguments() const {
  std::vector<std::string> out;
  for (const Entry& e : entries_) e.write(out);
  return out;
}

}  // namespace beaconloc::cli
