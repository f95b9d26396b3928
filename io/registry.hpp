// A registry: a fixed list of named entries (element types, model plugins), found by name.
// Each registry is one explicit list in one file (elements/registry.cpp, models/plugins.cpp).
#pragma once
#include <span>
#include <string>
#include <string_view>

namespace femdyn {

template <class Entry>  // Entry has a `std::string_view name`
class Registry {
 public:
  constexpr explicit Registry(std::span<const Entry> entries) : entries_(entries) {}

  std::span<const Entry> entries() const { return entries_; }

  // The entry called `name`, or nullptr.
  const Entry* find(std::string_view name) const {
    for (const Entry& e : entries_)
      if (e.name == name) return &e;
    return nullptr;
  }

  // "a, b, c": the known names, for "unknown … (known: …)" messages.
  std::string names() const {
    std::string list;
    for (const Entry& e : entries_) list += (list.empty() ? "" : ", ") + std::string(e.name);
    return list;
  }

 private:
  std::span<const Entry> entries_;
};

}  // namespace femdyn
