// livo-config merge BASE --overlay A.yaml,B.yaml [--out FILE]: a config with overlays merged over it, as every
// process would read it (livo::Config::load with overlays), written as one file; what
// scripts/run_pipeline.sh --overlay runs the processes on.
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/config/merged_config.hpp"
#include "livo/config_overlays.hpp"
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
    const std::string text = livo::config::mergedConfig(
        cli.get("BASE"), livo::overlayFiles(cli.has("--overlay") ? cli.get("--overlay") : std::string()));
    if (!cli.has("--out")) {
      std::cout << text;
      return 0;
    }
    std::string error;
    if (!livo::writeFileAtomically(cli.get("--out"), {text}, &error)) {
      std::cerr << "livo-config: " << error << "\n";
      return 1;
    }
  } catch (const std::exception& e) {
    std::cerr << "livo-config: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
