// Names and other user text in messages and tables. A name that reaches the terminal is
// refused if it holds a control character (C0, DEL, or C1 such as U+009B, which terminals read
// as escape sequences); text echoed back in an error (an unknown name, a malformed number) is
// escaped instead, so that no input can rewrite the user's terminal (core/model/message.hpp:
// escaped(), first_control(); every error message is escaped as a whole as well).
#pragma once
#include <string>
#include <string_view>

#include "core/model/errors.hpp"

namespace femdyn {

// User text as a message echoes it: escaped and cut to kMaxEchoBytes (with "…").
inline std::string echo_text(std::string_view s) { return escaped(truncated(s)); }

// 'name', as echo_text: for echoing user text in a message.
inline std::string quoted_text(std::string_view s) { return "'" + echo_text(s) + "'"; }

// Refuses a name with a control character, naming where and showing it escaped.
inline void check_name(std::string_view name, const std::string& where, const std::string& what) {
  if (first_control(name) != std::string_view::npos)
    throw ModelError(where, what + " " + quoted_text(name) +
                                " contains a control character (names must be printable)");
}

}  // namespace femdyn
