// The one place where user text becomes message text. Every femdyn error (femdyn::Error and its
// subclasses, core/model/errors.hpp) passes its whole formatted message through safe_message() in
// its constructor, and the two places where errors leave femdyn — the command line's main() and the
// Python module's exception translation — pass whatever reaches them through it once more. So a
// message is one line of printable text whatever it echoes: no control character (C0, DEL, C1
// such as U+009B, which terminals read as escape sequences), no line break, no byte that is not
// UTF-8, and a bounded length. Escaping is idempotent: "\x1b" stays "\x1b".
#pragma once
#include <cstdio>
#include <string>
#include <string_view>

namespace femdyn {

// An echoed piece of user text (quoted_text, core/model/names.hpp) keeps at most this many bytes.
constexpr std::size_t kMaxEchoBytes = 200;
// A whole message keeps at most this many bytes of its text before escaping (its start and its
// end, where the problem is said).
constexpr std::size_t kMaxMessageBytes = 4000;

namespace message_detail {

inline unsigned char byte(std::string_view s, std::size_t i) {
  return static_cast<unsigned char>(s[i]);
}

// The length of the well-formed UTF-8 sequence at s[i], or 0 if there is none.
inline std::size_t utf8_length(std::string_view s, std::size_t i) {
  const unsigned char c = byte(s, i);
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xbf;  // the second byte's range
  if (c < 0x80) return 1;
  if (c >= 0xc2 && c <= 0xdf) {
    n = 2;
  } else if (c >= 0xe0 && c <= 0xef) {  // no overlong form, no UTF-16 surrogate
    n = 3;
    lo = c == 0xe0 ? 0xa0 : 0x80;
    hi = c == 0xed ? 0x9f : 0xbf;
  } else if (c >= 0xf0 && c <= 0xf4) {  // no overlong form, nothing past U+10FFFF
    n = 4;
    lo = c == 0xf0 ? 0x90 : 0x80;
    hi = c == 0xf4 ? 0x8f : 0xbf;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    const unsigned char b = byte(s, i + k);
    if (b < (k == 1 ? lo : 0x80) || b > (k == 1 ? hi : 0xbf)) return 0;
  }
  return n;
}

// One character of s at s[i]: its length in bytes, and whether it is written as \xNN: a C0
// control or DEL, a C1 control U+0080 to U+009F (its 2 bytes), a byte that starts no UTF-8
// sequence (1 byte).
struct Char {
  std::size_t length;
  bool unsafe;
};

inline Char char_at(std::string_view s, std::size_t i) {
  const unsigned char c = byte(s, i);
  if (c < 0x20 || c == 0x7f) return {1, true};
  if (c < 0x80) return {1, false};
  const std::size_t n = utf8_length(s, i);
  if (n == 0) return {1, true};
  return {n, n == 2 && c == 0xc2 && byte(s, i + 1) <= 0x9f};
}

// The largest k ≤ at that does not fall inside a UTF-8 sequence of s.
inline std::size_t boundary_before(std::string_view s, std::size_t at) {
  if (at >= s.size()) return s.size();
  std::size_t k = at;
  while (k > 0 && at - k < 3 && (byte(s, k) & 0xc0) == 0x80) --k;
  return utf8_length(s, k) > at - k ? k : at;
}

}  // namespace message_detail

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

// s with every control character and every byte that is not UTF-8 written as \xNN (the rest as
// is). Idempotent: its output has no such byte.
inline std::string escaped(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const message_detail::Char ch = message_detail::char_at(s, i);
    if (!ch.unsafe) {
      out.append(s.substr(i, ch.length));
    } else {
      for (std::size_t k = 0; k < ch.length; ++k) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "\\x%02x", message_detail::byte(s, i + k));
        out += buf;
      }
    }
    i += ch.length;
  }
  return out;
}

// True if s is one line of printable UTF-8 text: what every message must be (the fuzz targets'
// and the tests' check).
inline bool printable_text(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    const message_detail::Char ch = message_detail::char_at(s, i);
    if (ch.unsafe) return false;
    i += ch.length;
  }
  return true;
}

// s cut to at most `max` bytes at a character boundary, with "…" if it was cut.
inline std::string truncated(std::string_view s, std::size_t max = kMaxEchoBytes) {
  if (s.size() <= max) return std::string(s);
  return std::string(s.substr(0, message_detail::boundary_before(s, max))) + "…";
}

// A message as it may reach a terminal or a Python exception: its start and end if it is
// longer than kMaxMessageBytes (joined by " … "), then escaped.
inline std::string safe_message(std::string_view text) {
  if (text.size() <= kMaxMessageBytes) return escaped(text);
  using message_detail::boundary_before;
  const std::size_t head = boundary_before(text, kMaxMessageBytes * 3 / 4);
  std::size_t tail = text.size() - kMaxMessageBytes / 4;
  while (tail < text.size() && (message_detail::byte(text, tail) & 0xc0) == 0x80) ++tail;
  return escaped(text.substr(0, head)) + " … " + escaped(text.substr(tail));
}

// The one sentence for a result that is NaN or Inf at a state that is finite (every door says
// it so): "at this state <what> is NaN or Inf (the state or the forces overflow double
// precision)"; "are" for a plural `what`.
inline std::string overflow_text(std::string_view what, bool plural = false) {
  return "at this state " + std::string(what) + (plural ? " are" : " is") +
         " NaN or Inf (the state or the forces overflow double precision)";
}

}  // namespace femdyn
