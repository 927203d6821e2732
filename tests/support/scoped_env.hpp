#pragma once
// An environment variable set for a scope (the child processes started in it inherit it), then
// put back as it was.
#include <stdlib.h>

#include <optional>
#include <string>

namespace beaconloc::testing {

class ScopedEnv {
 public:
  ScopedEnv(std::string name, const std::string& value) : name_(std::move(name)) {
    if (const char* old = ::getenv(name_.c_str())) old_ = old;
    ::setenv(name_.c_str(), value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_.c_str(), old_->c_str(), 1);
    } else {
      ::unsetenv(name_.c_str());
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;
  // The variable's value now with `option` appended, ':'-separated (sanitizer options).
  static std::string with_option(const std::string& name, const std::string& option) {
    const char* v = ::getenv(name.c_str());
    return v && *v ? std::string(v) + ":" + option : option;
  }

 private:
  std::string name_;
  std::optional<std::string> old_;
};

}  // namespace beaconloc::testing
