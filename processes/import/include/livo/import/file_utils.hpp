// Small file-system helpers shared by the folder importers.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace livo::import {

bool isDirectory(const std::string& path);
bool isFile(const std::string& path);
/// Names (not paths) of the regular files in `dir` ending in `suffix`, sorted; empty if no dir.
std::vector<std::string> listFiles(const std::string& dir, const std::string& suffix);
/// Whole file; throws std::runtime_error naming the file.
std::vector<uint8_t> readFileBytes(const std::string& path);
/// Lines of a text file without trailing '\r'; throws std::runtime_error naming the file.
std::vector<std::string> readLines(const std::string& path);
std::string joinPath(const std::string& a, const std::string& b);

}  // namespace livo::import
