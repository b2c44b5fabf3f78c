#pragma once
// Numbers in log lines: fixed-point text with a given number of decimals (result files use
// io::format_number, the shortest round-trip form, instead).
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

}  // namespace shroudsim
