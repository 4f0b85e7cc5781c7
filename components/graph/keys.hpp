#pragma once
// Key files for ZeroMQ CURVE (docs/security.md). `NAME.key` holds a secret key and must be
// private to its owner (mode 0600); `NAME.pub` holds the public key that goes with it. Each is one
// line of Z85 text; lines starting with '#' are comments. Graph files name key files, never keys:
// a reference `keys/solve` means keys/solve.key or keys/solve.pub, whichever the end needs.

#include <filesystem>
#include <string>
#include <vector>

#include "graph/transport.hpp"

namespace mocap::graph {

class Context;

// Where `mocap keys generate` writes and bare key names are found: $MOCAP_KEY_DIR, else
// $XDG_CONFIG_HOME/mocap/keys, else ~/.config/mocap/keys.
std::filesystem::path default_key_dir();

// A key reference as written in a graph file, as a path without extension: a bare name ("solve",
// no '/') is looked up in default_key_dir(); "~/..." is under $HOME; another relative path is
// relative to `base` (the graph file's folder); an absolute path stays.
std::string resolve_key_reference(const std::string& reference, const std::filesystem::path& base);
// Why `reference` cannot name key files ("" when it can): empty, or a key pasted in.
std::string key_reference_problem(const std::string& reference);

// Read and check one key file; throw mocap::InputError naming the file. A secret key file must be
// a regular file of this user that no one else may read or write; a public key file must not be
// writable by others (they could put their own key in it).
std::string read_public_key_file(const std::string& path);
std::string read_secret_key_file(const std::string& path);
// The public keys a reference names: every *.pub of a directory (an allow-list folder), else
// REFERENCE.pub. A reference that is neither is an error naming REFERENCE.pub.
std::vector<std::string> read_public_keys(const std::string& resolved_reference);

// The CURVE keys of one socket from resolved references (see CurveSpec in graph_spec.hpp): a
// binding end reads SERVER.key and every client's public keys, a connecting end SERVER.pub and
// CLIENT.key (exactly one client).
CurveKeys load_curve_keys(const std::string& server, const std::vector<std::string>& clients,
                          bool binds);

// The keys of a node that opens its own socket (Contract::network_socket), from its parameters
// curve_server and curve_client as validation resolved them; empty keys when they are not set.
CurveKeys node_curve_keys(const Context& ctx, bool binds);

struct WrittenKeyPair {
  std::string secret_file, public_file;
  std::string public_key;
};
// `mocap keys generate`: writes DIR/NAME.key (mode 0600) and DIR/NAME.pub. Refuses to replace
// existing files unless `force`. Throws std::runtime_error naming the file.
WrittenKeyPair write_key_pair(const std::string& name, const std::filesystem::path& dir,
                              bool force);

}  // namespace mocap::graph
