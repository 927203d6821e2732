#include "beaconloc/core/yaml_document.hpp"

#include <yaml-cpp/eventhandler.h>

#include <map>
#include <sstream>
#include <vector>

namespace beaconloc {
namespace {

// Walks the parser's events (each node once, an alias not expanded) and checks the keys of
// every mapping as they come.
class StrictKeys : public YAML::EventHandler {
 public:
  explicit StrictKeys(std::string origin) : origin_(std::move(origin)) {}

  void OnDocumentStart(const YAML::Mark& mark) override {
    if (documents_++ > 0) fail(mark, "a second YAML document (a file holds one)");
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { leaf(mark, "~"); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override {
    if (expecting_key()) {
      stack_.back().key.clear();  // name the mapping, not its previous key
      fail(mark, "'" + path() + "' has a key that is an alias");
    }
    leaf(mark, "");
  }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string& value) override {
    leaf(mark, value);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    open(mark, false);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    open(mark, true);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Collection {
    bool mapping = false;
    bool in_value = false;                 // mapping: the next node is the value of `key`
    std::string key;                       // mapping: the current key ("?" when not a scalar)
    long index = -1;                       // sequence: the current item
    std::map<std::string, int> key_lines;  // mapping: each key's line (0-based)
  };

  bool expecting_key() const { return !stack_.empty() && stack_.back().mapping && !stack_.back().in_value; }

  // A node starts: as a key, a mapping's value or a sequence's item.
  void start(const YAML::Mark& mark, const std::string* key) {
    if (stack_.empty()) return;
    Collection& c = stack_.back();
    if (!c.mapping) {
      ++c.index;
      return;
    }
    if (c.in_value) return;
    c.key = key ? *key : "?";
    if (!key) return;  // a key that is a sequence or a mapping: the schema refuses it by name
    const auto [at, fresh] = c.key_lines.emplace(*key, mark.line);
    if (!fresh)
      fail(mark, "'" + path() + "' is repeated (first at line " + std::to_string(at->second + 1) + ")");
  }
  // A node ended: a key is followed by its value, a value by the next key.
  void finish() {
    if (!stack_.empty() && stack_.back().mapping) stack_.back().in_value = !stack_.back().in_value;
  }
  void leaf(const YAML::Mark& mark, const std::string& value) {
    start(mark, &value);
    finish();
  }
  void open(const YAML::Mark& mark, bool mapping) {
    start(mark, nullptr);
    stack_.push_back(Collection{mapping, false, {}, -1, {}});
  }
  void close() {
    stack_.pop_back();
    finish();
  }

  // The dotted path to the current node: "beacons[2].id".
  std::string path() const {
    std::string p;
    for (const auto& c : stack_) {
      if (c.mapping) {
        if (c.key.empty()) continue;
        p += (p.empty() ? "" : ".") + c.key;
      } else if (c.index >= 0) {
        p += "[" + std::to_string(c.index) + "]";
      }
    }
    return p.empty() ? "the document" : p;
  }

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& what) const {
    // yaml-cpp marks lines from 0.
    throw YamlError(origin_ + ":" + std::to_string(mark.line + 1) + ": " + what);
  }

  std::string origin_;
  int documents_ = 0;
  std::vector<Collection> stack_;
};

}  // namespace

YAML::Node load_yaml(const std::string& text, const std::string& origin) {
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    StrictKeys keys(origin);
    while (parser.HandleNextDocument(keys)) {
    }
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw YamlError(origin + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
}

}  // namespace beaconloc
