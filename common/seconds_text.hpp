// Timestamps written as decimal seconds ("976052905.167303", "1.13486e+09", "-0.5") read into
// integer microseconds exactly, from the digits, with no binary floating point in between: a
// stamp read by a log driver and the same stamp read from a ground-truth file (the relations of
// Kümmerle et al.) give the same microsecond, so one can be found from the other by equality.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace traverse {

// Largest magnitude accepted [s]: beyond it a number is not seconds since any epoch a robot log
// could have (and microseconds would approach int64's range).
inline constexpr double kMaxSecondsText = 1e11;

// The whole token as [+-]digits[.digits][(e|E)[+-]digits] seconds, rounded to the nearest
// microsecond (halves away from zero). nullopt for anything else ("nan", "inf", "0x10", "1.",
// ".5" are accepted only in the forms above: "1." and ".5" are), and beyond kMaxSecondsText.
std::optional<int64_t> seconds_text_to_utime(std::string_view token);

}  // namespace traverse
