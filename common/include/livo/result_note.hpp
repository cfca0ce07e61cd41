// A result's note: the remarks of one step (a sweep, a frame) joined by "; ", in the order they arose.
#pragma once

#include <string>

namespace livo {

/// Appends `what` to `note`, after a "; " if the note already says something (a null note: nothing).
inline void appendNote(std::string* note, const std::string& what) {
  if (!note) return;
  if (!note->empty()) *note += "; ";
  *note += what;
}

}  // namespace livo
