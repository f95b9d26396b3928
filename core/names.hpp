// Names and other user text in messages and tables. A name that reaches the terminal is
// refused if it holds a control character (C0, DEL, or C1 such as U+009B, which terminals read
// as escape sequences); text echoed back in an error (an unknown name, a malformed number) is
// escaped instead, so that no input can rewrite the user's terminal.
#pragma once
#include <cstdio>
#include <string>
#include <string_view>

#include "core/errors.hpp"

namespace femdyn {

// The byte offset of the first control character (C0, DEL, or UTF-8 C1), or npos.
inline std::size_t first_control(std::string_view s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c == 0x7f) return i;
    if (c == 0xc2 && i + 1 < s.size() && static_cast<unsigned char>(s[i + 1]) >= 0x80 &&
        static_cast<unsigned char>(s[i + 1]) <= 0x9f)
      return i;
  }
  return std::string_view::npos;
}

// s with every control byte written as \xNN (the rest as is).
inline std::string escaped(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    const bool c1 = c == 0xc2 && i + 1 < s.size() && static_cast<unsigned char>(s[i + 1]) >= 0x80 &&
                    static_cast<unsigned char>(s[i + 1]) <= 0x9f;
    if (c < 0x20 || c == 0x7f || c1) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
      if (c1) {
        std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned char>(s[++i]));
        out += buf;
      }
    } else {
      out += s[i];
    }
  }
  return out;
}

// 'name', escaped: for echoing user text in a message.
inline std::string quoted_text(std::string_view s) { return "'" + escaped(s) + "'"; }

// Refuses a name with a control character, naming where and showing it escaped.
inline void check_name(std::string_view name, const std::string& where, const std::string& what) {
  if (first_control(name) != std::string_view::npos)
    throw ModelError(where, what + " " + quoted_text(name) +
                                " contains a control character (names must be printable)");
}

}  // namespace femdyn
