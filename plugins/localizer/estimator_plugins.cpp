#include "estimator_plugins.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <mutex>
#include <set>

#include "beaconloc/core/estimator_plugin.hpp"

namespace beaconloc {
namespace {

namespace fs = std::filesystem;

std::mutex& loaded_mutex() {
  static std::mutex m;
  return m;
}

std::set<std::string>& loaded_files() {
  static std::set<std::string> files;  // real paths
  return files;
}

// The file each plugin estimator came from, for the message when another plugin takes its name.
std::map<std::string, std::string>& plugin_of_estimator() {
  static std::map<std::string, std::string> files;
  return files;
}

[[noreturn]] void refuse(const std::string& file, const std::string& why) {
  throw EstimatorPluginError("estimator plugin " + file + ": " + why);
}

std::string dl_error() {
  const char* e = dlerror();
  return e ? e : "unknown error";
}

// The plugin's symbol, or null.
void* symbol(void* handle, const char* name) {
  dlerror();
  return dlsym(handle, name);
}

std::vector<std::string> load_file(const std::string& file) {
  std::error_code ec;
  const std::string real = fs::canonical(file, ec).string();
  if (ec) refuse(file, "cannot be read (" + ec.message() + ")");
  if (loaded_files().count(real)) return {};
  // Said before the plugin's own code runs (its static initializers, in dlopen): a plugin that
  // ends the process there is named in the log (the journal, under systemd).
  std::cerr << "beaconloc: loading estimator plugin " << real << '\n';
  // RTLD_LOCAL: a plugin's symbols (its own copy of the SDK's code) serve it alone; RTLD_NOW: an
  // undefined symbol is found now, with its name, not at the first call.
  void* handle = dlopen(real.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) refuse(file, "cannot be loaded: " + dl_error());
  const auto close = [&] { dlclose(handle); };
  const auto abi = reinterpret_cast<PluginAbiFunction>(symbol(handle, kPluginAbiSymbol));
  const auto registry_of = reinterpret_cast<PluginRegistryFunction>(symbol(handle, kPluginRegistrySymbol));
  if (!abi || !registry_of) {
    close();
    refuse(file, std::string("is not a beaconloc estimator plugin (no ") + kPluginAbiSymbol + "/" +
                     kPluginRegistrySymbol +
                     "; see BEACONLOC_ESTIMATOR_PLUGIN() in beaconloc/core/estimator_plugin.hpp)");
  }
  const std::string plugin_abi = abi() ? abi() : "";
  if (plugin_abi != BEACONLOC_SDK_ABI) {
    close();
    refuse(file, "was built against another SDK: '" + plugin_abi +
                     "', this localizer is '" BEACONLOC_SDK_ABI "' (beaconloc " BEACONLOC_SDK_VERSION
                     "): rebuild it against this SDK (find_package(beaconloc " +
                     std::to_string(BEACONLOC_SDK_VERSION_MAJOR) + "." +
                     std::to_string(BEACONLOC_SDK_VERSION_MINOR) + "))");
  }
  const EstimatorRegistry* plugin = registry_of();
  EstimatorRegistry& host = EstimatorRegistry::instance();
  if (plugin == &host) {
    // Its code bound to the localizer's own registry: it was linked without hiding the SDK's
    // symbols, and its estimators went nowhere the check above could see.
    close();
    refuse(file, "shares the localizer's registry: build it with beaconloc_add_estimator_plugin()");
  }
  const std::vector<std::string> names = plugin ? plugin->names() : std::vector<std::string>{};
  if (names.empty()) {
    close();
    refuse(file, "registers no estimator (BEACONLOC_REGISTER_ESTIMATOR)");
  }
  for (const std::string& name : names) {
    if (!host.factory(name)) continue;
    close();
    const auto first = plugin_of_estimator().find(name);
    refuse(file, "registers estimator '" + name + "', which this localizer has already (" +
                     (first == plugin_of_estimator().end() ? "built in" : "from " + first->second) + ")");
  }
  for (const std::string& name : names) {
    host.add(name, plugin->description(name), plugin->reference_scenario(name), plugin->factory(name));
    plugin_of_estimator()[name] = real;
  }
  loaded_files().insert(real);  // never closed: the registry holds its factories
  return names;
}

std::vector<std::string> plugin_files(const std::string& path) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return {path};
  std::vector<std::string> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(path, ec)) {
    if (entry.path().extension() == ".so" && !entry.is_directory()) files.push_back(entry.path().string());
  }
  if (ec) refuse(path, "cannot be listed (" + ec.message() + ")");
  if (files.empty()) refuse(path, "is a directory without any *.so file");
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

std::vector<std::string> load_estimator_plugins(const std::vector<std::string>& paths) {
  const std::lock_guard<std::mutex> lock(loaded_mutex());
  std::vector<std::string> added;
  for (const std::string& path : paths) {
    for (const std::string& file : plugin_files(path)) {
      const std::vector<std::string> names = load_file(file);
      added.insert(added.end(), names.begin(), names.end());
    }
  }
  return added;
}

}  // namespace beaconloc
