// livo-config merge BASE --overlay A.yaml,B.yaml [--out FILE]: a config with overlays merged over it, as every
// process would read it (livo::Config::load with overlays), written as one file; what
// scripts/run_pipeline.sh --overlay runs the processes on.
#include <iostream>
#include <sstream>

#include "livo/command_line.hpp"
#include "livo/config.hpp"
#include "livo/file_output.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli("livo-config",
                        "merge BASE --overlay FILES: BASE with the overlays merged over it in order (maps key by key, "
                        "any other value replaced), checked and written to --out (or printed).");
  cli.positional("COMMAND", "merge");
  cli.positional("BASE", "the config file");
  cli.option("--overlay", "FILES", "comma-separated overlay files, merged in order");
  cli.option("--out", "FILE", "write the merged config here (default: standard output)");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (cli.get("COMMAND") != "merge") {
    std::cerr << "livo-config: unknown command '" << cli.get("COMMAND") << "'\n" << cli.usage();
    return 2;
  }
  try {
    const std::string base = cli.get("BASE");
    std::vector<std::string> overlays;
    std::stringstream list(cli.has("--overlay") ? cli.get("--overlay") : std::string());
    for (std::string f; std::getline(list, f, ',');)
      if (!f.empty()) overlays.push_back(f);
    const livo::Config merged = livo::Config::load(base, overlays);
    merged.checkKeysIn(livo::kConfigSections);
    std::string header = "# livo-config merge: " + base;
    for (const std::string& o : overlays) header += " + " + o;
    header += "\n";
    const std::string text = livo::Config::mergedText(base, overlays);
    if (!cli.has("--out")) {
      std::cout << header << text;
      return 0;
    }
    std::string error;
    if (!livo::writeFileAtomically(cli.get("--out"), {header, text}, &error)) {
      std::cerr << "livo-config: " << error << "\n";
      return 1;
    }
  } catch (const std::exception& e) {
    std::cerr << "livo-config: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
