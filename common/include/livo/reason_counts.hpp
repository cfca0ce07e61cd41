// How often each reason for refusing something came up (an image a VIO did not use, a prior it
// kept), as a node's exit summary on HEALTH that a report can read back.
//
// Reasons with numbers in them are grouped by their text up to the first " (" ("too few patches
// (12)" and "too few patches (9)" are one reason). summary() writes
//   "<what> by reason: 20 x no image at the prior's time; 17 x too few patches"
// most frequent first, and parseReasonCounts() reads it back.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

namespace livo {

class ReasonCounts {
 public:
  void add(const std::string& why, int64_t times = 1);
  int64_t total() const;
  bool empty() const { return counts_.empty(); }
  const std::map<std::string, int64_t>& counts() const { return counts_; }
  /// The reason `why` is counted under: its text up to the first " (", without ';' (the separator).
  static std::string key(const std::string& why);
  /// "<what> by reason: N x reason; ..." (most frequent first, then by name); empty when none.
  std::string summary(const std::string& what) const;

 private:
  std::map<std::string, int64_t> counts_;
};

struct ParsedReasonCounts {
  std::string what;
  ReasonCounts reasons;
};

/// Reads a ReasonCounts::summary() back (nullopt for any other text).
std::optional<ParsedReasonCounts> parseReasonCounts(const std::string& text);

}  // namespace livo
