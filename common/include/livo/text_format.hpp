// Numbers in log lines and notes; text inside markup (SVG, HTML).
#pragma once

#include <sstream>
#include <string>

namespace livo {

/// `v` with `digits` significant digits, as an ostream prints it (0.0123, 1.5e+03).
inline std::string formatSignificant(double v, int digits = 3) {
  std::ostringstream os;
  os.precision(digits);
  os << v;
  return os.str();
}

/// `v` with `digits` digits after the point (1.50, 0.0), as std::fixed prints it.
inline std::string formatFixed(double v, int digits) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(digits);
  os << v;
  return os.str();
}

/// `s` safe as XML / HTML text or a quoted attribute value: & < > " ' as entities.
inline std::string escapeMarkup(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace livo
