#pragma once
// Numbers as text: fixed-point with a given number of decimals (log lines), and the shortest
// text that reads back to the same double (result files through io::format_number, messages).
#include <charconv>
#include <sstream>
#include <string>

namespace shroudsim {

inline std::string fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

/// Shortest text that reads back to v ("0.5", "1e-08", "2.1e+11"; std::to_chars).
inline std::string shortest(double v) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

}  // namespace shroudsim
