#pragma once
// Fast fixed-point formatting of numbers for text outputs (.pos, RINEX, NMEA), the equivalent of printf's
// "%*.*f" and "%*d" without its per-call parsing and locale work: a .pos line costs a tenth of what snprintf does.

#include <string>

namespace canyon::io {

/// Appends `value` with `decimals` digits after the point (0..12), right-aligned in `width` characters, rounding half
/// away from zero on the decimal value (printf rounds the binary value: the two can differ in the last digit for
/// values within 1e-16 relative of a tie). NaN, infinities and |value| >= 1e15 fall back to snprintf.
void append_fixed(std::string& out, double value, int width, int decimals);

/// Appends an integer right-aligned in `width` characters ("%*lld").
void append_int(std::string& out, long long value, int width);

}  // namespace canyon::io
