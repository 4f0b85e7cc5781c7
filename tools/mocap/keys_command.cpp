// `mocap keys generate NAME [--dir DIR] [--force]`: a ZeroMQ CURVE key pair as two files, NAME.key
// (secret, mode 0600) and NAME.pub, for graph edges and endpoints that cross the network
// (graph/keys.hpp, docs/security.md).

#include <iostream>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "graph/keys.hpp"

namespace mocap::cli {
namespace {

int generate(int argc, char** argv) {
  Args args(
      "mocap keys generate NAME [--dir DIR] [--force]",
      "Makes a CURVE key pair for ZeroMQ: DIR/NAME.key holds the secret key (mode 0600: "
      "only you may read it) and DIR/NAME.pub the public key, each one line of Z85 text. A "
      "graph names the pair by its path without extension (curve: { server: DIR/NAME, ... }) "
      "or, when it lies in the default folder, by NAME alone. Give NAME.pub to the other end; "
      "never copy NAME.key anywhere else. Existing files are kept unless --force.");
  args.positional("NAME", "the key pair's name (letters, digits, '_', '-', '.')")
      .option("dir", "DIR",
              "where to write ($MOCAP_KEY_DIR, else $XDG_CONFIG_HOME/mocap/keys, else "
              "~/.config/mocap/keys; a new folder is made private)",
              graph::default_key_dir().string())
      .flag("force", "replace existing NAME.key and NAME.pub");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!graph::curve_available()) {
    throw InputError("mocap keys generate",
                     "this libzmq has no CURVE security (zmq_has(\"curve\") is false)");
  }
  const graph::WrittenKeyPair written =
      graph::write_key_pair(args.positionals().at(0), args.get("dir"), args.has("force"));
  std::cout << "secret key: " << written.secret_file << " (mode 0600; keep it here)\n"
            << "public key: " << written.public_file << " (" << written.public_key << ")\n";
  return 0;
}

}  // namespace

int keys_command(int argc, char** argv) {
  static constexpr Subcommand kSubcommands[] = {
      {"generate", "write a CURVE key pair: NAME.key (secret, 0600) and NAME.pub", generate},
  };
  return run_subcommand("keys", kSubcommands, argc, argv);
}

}  // namespace mocap::cli
