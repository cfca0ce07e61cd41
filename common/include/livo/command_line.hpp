// A small command-line parser shared by every executable: declared options only, `--help`,
// and clear errors for unknown options or missing values.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace livo {

class CommandLine {
 public:
  CommandLine(std::string program, std::string summary);

  /// `--name VALUE`; an empty default means "not given" (has() is false).
  CommandLine& option(const std::string& name, const std::string& value_name, const std::string& help,
                      const std::string& default_value = "");
  /// `--name` with no value.
  CommandLine& flag(const std::string& name, const std::string& help);
  /// Positional argument, in declaration order.
  CommandLine& positional(const std::string& name, const std::string& help, bool required = true);

  /// Parses argv. Returns false if the program should exit now, with exitCode() (0 after --help,
  /// 2 after a usage error, which is printed with the usage).
  bool parse(int argc, char** argv);
  int exitCode() const { return exit_code_; }

  bool has(const std::string& name) const;
  std::string get(const std::string& name) const;
  double getDouble(const std::string& name) const;
  int64_t getInt(const std::string& name) const;
  /// Extra positionals after the declared ones (e.g. a command to run).
  const std::vector<std::string>& rest() const { return rest_; }
  void allowRest(const std::string& name, const std::string& help);

  std::string usage() const;
  const std::string& program() const { return program_; }

 private:
  struct Opt {
    std::string name, value_name, help, value;
    bool is_flag = false;
    bool given = false;
  };
  std::string program_, summary_;
  std::vector<Opt> options_;
  std::vector<Opt> positionals_;
  std::vector<std::string> rest_;
  std::string rest_name_, rest_help_;
  bool allow_rest_ = false;
  int exit_code_ = 0;
  const Opt* find(const std::string& name) const;
};

}  // namespace livo
