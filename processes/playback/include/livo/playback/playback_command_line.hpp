// livo-playback's command line read into PlaybackOptions (main.cpp declares the flags).
#pragma once

#include "livo/command_line.hpp"
#include "livo/playback/playback.hpp"

namespace livo::playback {

/// The replay a parsed command line asks for; throws std::invalid_argument naming the flag (or the
/// fault) for a bad value.
PlaybackOptions playbackOptionsFromCommandLine(const CommandLine& cli);

}  // namespace livo::playback
