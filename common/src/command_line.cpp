#include "livo/command_line.hpp"

#include <cstdlib>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace livo {

CommandLine::CommandLine(std::string program, std::string summary)
    : program_(std::move(program)), summary_(std::move(summary)) {}

CommandLine& CommandLine::option(const std::string& name, const std::string& value_name, const std::string& help,
                                 const std::string& default_value) {
  Opt o;
  o.name = name;
  o.value_name = value_name;
  o.help = help;
  o.value = default_value;
  options_.push_back(o);
  return *this;
}

CommandLine& CommandLine::flag(const std::string& name, const std::string& help) {
  Opt o;
  o.name = name;
  o.help = help;
  o.is_flag = true;
  options_.push_back(o);
  return *this;
}

CommandLine& CommandLine::positional(const std::string& name, const std::string& help, bool required) {
  Opt o;
  o.name = name;
  o.help = help;
  o.is_flag = !required;  // reused: "optional" for positionals
  positionals_.push_back(o);
  return *this;
}

void CommandLine::allowRest(const std::string& name, const std::string& help) {
  allow_rest_ = true;
  rest_name_ = name;
  rest_help_ = help;
}

std::string CommandLine::usage() const {
  std::ostringstream os;
  os << "usage: " << program_;
  for (const auto& p : positionals_) os << (p.is_flag ? " [" : " ") << p.name << (p.is_flag ? "]" : "");
  if (!options_.empty()) os << " [options]";
  if (allow_rest_) os << " [" << rest_name_ << "...]";
  os << "\n" << summary_ << "\n";
  for (const auto& p : positionals_) os << "  " << p.name << "\n      " << p.help << "\n";
  if (allow_rest_) os << "  " << rest_name_ << "...\n      " << rest_help_ << "\n";
  for (const auto& o : options_) {
    os << "  " << o.name << (o.is_flag ? "" : " " + o.value_name) << "\n      " << o.help;
    if (!o.is_flag && !o.value.empty()) os << " (default: " << o.value << ")";
    os << "\n";
  }
  os << "  --help\n      show this text\n";
  return os.str();
}

bool CommandLine::parse(int argc, char** argv) {
  size_t next_positional = 0;
  bool only_positionals = false;
  auto fail = [&](const std::string& msg) {
    std::cerr << program_ << ": " << msg << "\n" << usage();
    exit_code_ = 2;
    return false;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (!only_positionals && a == "--help") {
      std::cout << usage();
      exit_code_ = 0;
      return false;
    }
    if (!only_positionals && a == "--") {
      only_positionals = true;
      continue;
    }
    if (!only_positionals && a.size() > 2 && a.compare(0, 2, "--") == 0) {
      std::string name = a, value;
      const size_t eq = a.find('=');
      const bool inline_value = eq != std::string::npos;
      if (inline_value) {
        name = a.substr(0, eq);
        value = a.substr(eq + 1);
      }
      Opt* o = nullptr;
      for (auto& c : options_)
        if (c.name == name) o = &c;
      if (!o) return fail("unknown option " + name);
      if (o->is_flag) {
        if (inline_value) return fail(name + " takes no value");
        o->given = true;
        continue;
      }
      if (!inline_value) {
        if (i + 1 >= argc) return fail(name + " needs a value (" + o->value_name + ")");
        value = argv[++i];
      }
      o->value = value;
      o->given = true;
      continue;
    }
    if (next_positional < positionals_.size()) {
      positionals_[next_positional].value = a;
      positionals_[next_positional].given = true;
      ++next_positional;
    } else if (allow_rest_) {
      rest_.assign(argv + i, argv + argc);
      break;
    } else {
      return fail("unexpected argument '" + a + "'");
    }
  }
  for (const auto& p : positionals_)
    if (!p.is_flag && !p.given) return fail("missing " + p.name);
  return true;
}

const CommandLine::Opt* CommandLine::find(const std::string& name) const {
  for (const auto& o : options_)
    if (o.name == name) return &o;
  for (const auto& p : positionals_)
    if (p.name == name) return &p;
  throw std::logic_error(program_ + ": option " + name + " was never declared");
}

bool CommandLine::has(const std::string& name) const {
  const Opt* o = find(name);
  return o->given || (!o->is_flag && !o->value.empty());
}

std::string CommandLine::get(const std::string& name) const { return find(name)->value; }

double CommandLine::getDouble(const std::string& name) const {
  const std::string v = get(name);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0') throw std::invalid_argument(name + ": expected a number, got '" + v + "'");
  return d;
}

int64_t CommandLine::getInt(const std::string& name) const {
  const std::string v = get(name);
  char* end = nullptr;
  const long long d = std::strtoll(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0') throw std::invalid_argument(name + ": expected an integer, got '" + v + "'");
  return d;
}

}  // namespace livo
