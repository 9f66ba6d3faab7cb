#include "tools/echo/lcm_type_registry.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "tools/echo/embedded_lcm_types.h"
#include "tools/echo/lcm_fingerprint.h"
#include "tools/echo/lcm_type_parser.h"

namespace resolver {

LcmTypeRegistry LcmTypeRegistry::with_embedded_types() {
  LcmTypeRegistry registry;
  for (const auto& file : embedded_lcm_files()) registry.add_text(file.text, file.path);
  return registry;
}

void LcmTypeRegistry::add_text(std::string_view text, std::string_view source_name) {
  std::vector<LcmStruct> parsed = parse_lcm_types(text, source_name);
  for (auto& s : parsed) {
    std::string key = s.full_name();
    by_name_.insert_or_assign(std::move(key), std::move(s));
  }
  rebuild_index();
}

void LcmTypeRegistry::add_directory(const std::filesystem::path& dir) {
  std::error_code ec;
  std::vector<std::filesystem::path> files;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().extension() == ".lcm") files.push_back(it->path());
  }
  if (ec) {
    throw LcmParseError(fmt::format("--types {}: cannot list the directory ({}); pass a directory holding .lcm files",
                                    dir.string(), ec.message()));
  }
  std::sort(files.begin(), files.end());
  for (const auto& path : files) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    if (in.is_open()) text << in.rdbuf();
    if (!in.is_open() || in.bad()) {
      throw LcmParseError(fmt::format("{}: cannot read the file; check its permissions", path.string()));
    }
    add_text(text.str(), path.string());
  }
}

void LcmTypeRegistry::rebuild_index() {
  by_fingerprint_.clear();
  fingerprint_by_name_.clear();
  problems_.clear();
  const LcmTypeLookup lookup = [this](const std::string& name) { return find_by_name(name); };
  for (const auto& [name, s] : by_name_) {
    try {
      const std::uint64_t fp = lcm_fingerprint(s, lookup);
      fingerprint_by_name_.emplace(name, fp);
      const auto [it, inserted] = by_fingerprint_.emplace(fp, &s);
      if (!inserted) {
        // Same layout under two names: the message cannot say which it is;
        // the first by name wins, deterministically.
        problems_.push_back(fmt::format("'{}' ({}) has the same fingerprint as '{}'; messages decode as '{}'", name,
                                        s.source, it->second->full_name(), it->second->full_name()));
      }
    } catch (const LcmTypeError& e) {
      problems_.push_back(e.what());
    }
  }
}

const LcmStruct* LcmTypeRegistry::find_by_name(std::string_view full_name) const {
  const auto it = by_name_.find(full_name);
  return it == by_name_.end() ? nullptr : &it->second;
}

const LcmStruct* LcmTypeRegistry::find_by_fingerprint(std::uint64_t fingerprint) const {
  const auto it = by_fingerprint_.find(fingerprint);
  return it == by_fingerprint_.end() ? nullptr : it->second;
}

std::optional<std::uint64_t> LcmTypeRegistry::fingerprint_of(std::string_view full_name) const {
  const auto it = fingerprint_by_name_.find(full_name);
  if (it == fingerprint_by_name_.end()) return std::nullopt;
  return it->second;
}

std::vector<const LcmStruct*> LcmTypeRegistry::types() const {
  std::vector<const LcmStruct*> out;
  for (const auto& [name, s] : by_name_) out.push_back(&s);
  return out;
}

}  // namespace resolver
