// Security of the network edges (docs/security.md): CURVE key files (made, read, refused), the
// graph rules (loopback unless allowed, keys beyond loopback, files never keys), and real sockets
// on tcp://127.0.0.1 with CURVE on: the right client gets through; a client without keys, with a
// key the server does not list, or with a wrong server key gets nothing through and the server
// logs the refusal. Plugins that others could change are refused.

#include <dlfcn.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <thread>
#include <zmq.hpp>

#include "core/input_error.hpp"
#include "graph/keys.hpp"
#include "graph/plugins.hpp"
#include "graph/transport.hpp"
#include "graph/validation.hpp"
#include "graph_test_util.hpp"

namespace mocap::graph {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;
using namespace std::chrono_literals;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

mode_t mode_of(const std::string& path) {
  struct stat info {};
  stat(path.c_str(), &info);
  return info.st_mode & 07777;
}

class Keys : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!curve_available()) GTEST_SKIP() << "this libzmq has no CURVE (zmq_has(\"curve\"))";
  }
  // Makes NAME.key / NAME.pub in the temporary folder; returns the reference (path, no extension).
  std::string make(const std::string& name) {
    write_key_pair(name, dir_.path(), false);
    return dir_.file(name);
  }
  TempDir dir_;
};

TEST_F(Keys, GenerateWritesAPrivateSecretAndAPublicKeyAndKeepsExistingFiles) {
  const WrittenKeyPair written = write_key_pair("solve", dir_.path() / "new" / "keys", false);
  EXPECT_EQ(mode_of(written.secret_file), 0600u);
  EXPECT_EQ(mode_of((dir_.path() / "new" / "keys").string()), 0700u);  // a new folder is private
  const std::string secret = read_secret_key_file(written.secret_file);
  const std::string pub = read_public_key_file(written.public_file);
  EXPECT_EQ(pub, written.public_key);
  EXPECT_EQ(curve_public_key(secret), pub);  // the two files belong together
  EXPECT_EQ(testing::read_file(written.secret_file).find(pub), std::string::npos);

  const std::string refusal =
      error_of([&] { write_key_pair("solve", dir_.path() / "new" / "keys", false); });
  EXPECT_NE(refusal.find("solve.key exists; pass --force"), std::string::npos) << refusal;
  EXPECT_EQ(read_secret_key_file(written.secret_file), secret);  // untouched
  const WrittenKeyPair again = write_key_pair("solve", dir_.path() / "new" / "keys", true);
  EXPECT_NE(read_secret_key_file(again.secret_file), secret);
  EXPECT_EQ(mode_of(again.secret_file), 0600u);

  EXPECT_NE(error_of([&] { write_key_pair("../escape", dir_.path(), false); }).find("key name"),
            std::string::npos);
}

TEST_F(Keys, KeyFilesOthersCouldReadOrChangeAreRefusedNamingTheFile) {
  const std::string ref = make("capture");
  chmod((ref + ".key").c_str(), 0640);
  std::string e = error_of([&] { read_secret_key_file(ref + ".key"); });
  EXPECT_NE(e.find(ref + ".key"), std::string::npos) << e;
  EXPECT_NE(e.find("mode 0640"), std::string::npos) << e;
  EXPECT_NE(e.find("chmod 600"), std::string::npos) << e;
  chmod((ref + ".key").c_str(), 0604);
  EXPECT_NE(error_of([&] { read_secret_key_file(ref + ".key"); }).find("mode 0604"),
            std::string::npos);
  chmod((ref + ".pub").c_str(), 0646);
  e = error_of([&] { read_public_key_file(ref + ".pub"); });
  EXPECT_NE(e.find("others can write"), std::string::npos) << e;
  e = error_of([&] { read_public_key_file(dir_.file("nothing.pub")); });
  EXPECT_NE(e.find("nothing.pub: no such key file"), std::string::npos) << e;
}

TEST_F(Keys, GarbageKeyFilesAreRefusedNamingTheFile) {
  const std::vector<std::string> contents = {
      "",
      "# only a comment\n",
      "short\n",
      std::string(5000, 'a'),
      "rq:rM>}U?@Lns47E1%kR.o@n%FcmmsL/@{H8]yf7\nrq:rM>}U?@Lns47E1%kR.o@n%FcmmsL/@{H8]yf7\n",
      std::string("\0\x01\xff\x80garbage\n", 12),
      "rq:rM>}U?@Lns47E1%kR.o@n%FcmmsL/@{H8]yf\xc3\n"};
  for (std::size_t i = 0; i < contents.size(); ++i) {
    const std::string file = dir_.file("bad" + std::to_string(i) + ".pub");
    testing::write_file(file, contents[i]);
    const std::string e = error_of([&] { read_public_key_file(file); });
    EXPECT_NE(e.find(file + ": not a key file"), std::string::npos) << i << ": " << e;
  }
}

TEST_F(Keys, ReferencesResolveAgainstTheGraphFolderAndPastedKeysAreRefused) {
  EXPECT_EQ(resolve_key_reference("keys/solve", "/g"), "/g/keys/solve");
  EXPECT_EQ(resolve_key_reference("/etc/mocap/solve", "/g"), "/etc/mocap/solve");
  EXPECT_EQ(resolve_key_reference("solve", "/g"), (default_key_dir() / "solve").string());
  EXPECT_EQ(key_reference_problem("keys/solve"), "");
  const CurveKeyPair pair = generate_curve_key_pair();
  EXPECT_NE(key_reference_problem(pair.secret_key).find("looks like a key itself"),
            std::string::npos);
  EXPECT_NE(key_reference_problem(pair.public_key).find("never keys"), std::string::npos);
}

// --- validation

class Validation : public Keys {
 protected:
  std::string validate(const std::string& text) {
    const std::string file = dir_.file("g.yaml");
    testing::write_file(file, text);
    return error_of([&] { resolve(load_graph_file(file)); });
  }
  static std::string edge_graph(const std::string& options, bool allow_network = true) {
    return std::string(allow_network ? "allow_network: true\n" : "") +
           "nodes:\n"
           "  src: { type: test.counter, params: { count: 3 } }\n"
           "  sink: { type: test.collect, params: { path: /dev/null } }\n"
           "edges:\n"
           "  - [src.out, sink.in, " +
           options +
           "]\n"
           "processes:\n  capture: [src]\n  solve: [sink]\n";
  }
};

TEST_F(Validation, NetworkEdgesWithoutKeysAreRefused) {
  for (const std::string host : {"192.168.1.20", "0.0.0.0", "*", "[::]", "eth0"}) {
    const std::string e = validate(edge_graph("{ transport: \"tcp://" + host + ":5791\" }"));
    EXPECT_NE(
        e.find("g.yaml:6: edge src.out -> sink.in crosses the network (" + host + ") without keys"),
        std::string::npos)
        << e;
  }
  // Without allow_network both rules speak.
  const std::string e = validate(edge_graph("{ transport: \"tcp://10.0.0.2:5791\" }", false));
  EXPECT_NE(e.find("allow_network: true"), std::string::npos) << e;
  EXPECT_NE(e.find("without keys"), std::string::npos) << e;
  // Loopback needs neither.
  EXPECT_EQ(validate(edge_graph("{ transport: \"tcp://127.0.0.1:5791\" }", false)), "(no error)");
}

TEST_F(Validation, ANetworkEdgeWithKeyFilesValidates) {
  make("solve");
  make("capture");
  EXPECT_EQ(validate(edge_graph("{ transport: \"tcp://0.0.0.0:5791\", curve: { server: ./solve, "
                                "client: ./capture } }")),
            "(no error)");
  // Loopback may opt in.
  EXPECT_EQ(validate(edge_graph("{ transport: \"tcp://127.0.0.1:5791\", curve: { server: ./solve, "
                                "client: ./capture } }",
                                false)),
            "(no error)");
}

TEST_F(Validation, KeyProblemsAreNamedWithFileAndLine) {
  make("solve");
  make("capture");
  const CurveKeyPair pair = generate_curve_key_pair();
  // A key pasted into the graph.
  std::string e = validate(edge_graph("{ transport: \"tcp://0.0.0.0:5791\", curve: { server: \"" +
                                      pair.public_key + "\", client: ./capture } }"));
  EXPECT_NE(e.find("g.yaml:6: curve: this looks like a key itself"), std::string::npos) << e;
  // A missing file.
  e = validate(edge_graph(
      "{ transport: \"tcp://0.0.0.0:5791\", curve: { server: ./solve, client: ./nobody } }"));
  EXPECT_NE(e.find("g.yaml:6: " + dir_.file("./nobody.key") + ": no such key file"),
            std::string::npos)
      << e;
  // A secret key others may read.
  chmod(dir_.file("solve.key").c_str(), 0644);
  e = validate(edge_graph(
      "{ transport: \"tcp://0.0.0.0:5791\", curve: { server: ./solve, client: ./capture } }"));
  EXPECT_NE(e.find("solve.key: this secret key file is open to group or others (mode 0644)"),
            std::string::npos)
      << e;
  // Only half of the keys, or keys on an in-process edge.
  e = validate(edge_graph("{ transport: \"tcp://0.0.0.0:5791\", curve: { server: ./solve } }"));
  EXPECT_NE(e.find("curve needs server: (the consumer's key) and client:"), std::string::npos) << e;
  chmod(dir_.file("solve.key").c_str(), 0600);
  e = validate(edge_graph("{ curve: { server: ./solve, client: ./capture } }"));
  EXPECT_NE(e.find("curve keys need an ipc:// or tcp:// transport"), std::string::npos) << e;
}

TEST_F(Validation, EachProcessChecksOnlyTheKeyFilesItReads) {
  make("solve");
  make("capture");
  fs::remove(dir_.file("solve.key"));  // the consumer's host has it, this one does not
  const std::string text = edge_graph(
      "{ transport: \"tcp://0.0.0.0:5791\", curve: { server: ./solve, client: ./capture } }");
  testing::write_file(dir_.file("g.yaml"), text);
  GraphSpec spec = load_graph_file(dir_.file("g.yaml"));
  spec.local_process = "capture";  // the producer: solve.pub and capture.key
  EXPECT_EQ(error_of([&] { resolve(spec); }), "(no error)");
  spec.local_process = "solve";
  EXPECT_NE(error_of([&] { resolve(spec); }).find("solve.key: no such key file"),
            std::string::npos);
}

TEST_F(Validation, NodeEndpointsFollowTheSameRules) {
  make("server");
  make("viewer");
  const auto graph = [](const std::string& params) {
    return "allow_network: true\nnodes:\n"
           "  src: { type: test.counter, params: { count: 3 } }\n"
           "  pub: { type: sink.publish, params: { " +
           params + " } }\nedges:\n  - [src.out, pub.in]\n";
  };
  std::string e = validate(graph("endpoint: \"tcp://*:5560\""));
  EXPECT_NE(e.find("g.yaml:4: node 'pub': tcp://*:5560 crosses the network (*) without keys"),
            std::string::npos)
      << e;
  e = validate(
      "nodes:\n  remote: { type: source.remote_keypoints, params: { endpoint: "
      "\"tcp://0.0.0.0:5570\" } }\n"
      "  sink: { type: test.collect, params: { path: /dev/null } }\nedges:\n"
      "  - [remote.out, sink.in]\n");
  EXPECT_NE(e.find("allow_network"), std::string::npos) << e;
  EXPECT_NE(e.find("without keys"), std::string::npos) << e;
  EXPECT_EQ(validate(graph("endpoint: \"tcp://*:5560\", curve_server: ./server, curve_client: "
                           "\"./viewer, ./server\"")),
            "(no error)");
  const CurveKeyPair pair = generate_curve_key_pair();
  e = validate(graph("endpoint: \"tcp://*:5560\", curve_server: ./server, curve_client: \"" +
                     pair.public_key + "\""));
  EXPECT_NE(e.find("g.yaml:4: node 'pub': curve_client: this looks like a key itself"),
            std::string::npos)
      << e;
  e = validate(graph("endpoint: \"tcp://127.0.0.1:5560\", curve_server: ./server"));
  EXPECT_NE(e.find("curve_server and curve_client go together"), std::string::npos) << e;
}

// --- sockets with CURVE on tcp://127.0.0.1

Packet numbered(std::uint64_t seq) {
  auto m = std::make_shared<People2D>();
  m->header = {"s", seq, 1, static_cast<std::int64_t>(seq)};
  m->people.push_back(Person2D{static_cast<int>(seq), {{1, 2, 3}}, {}});
  return Packet::of<People2D>(m);
}

// Receives up to `wait`; the number of valid messages.
int count_received(Receiver& receiver, std::chrono::milliseconds wait) {
  int received = 0;
  const auto deadline = std::chrono::steady_clock::now() + wait;
  while (std::chrono::steady_clock::now() < deadline) {
    if (receiver.receive(50ms).message) ++received;
  }
  return received;
}

class CurveSockets : public Keys {
 protected:
  void SetUp() override {
    Keys::SetUp();
    if (IsSkipped()) return;
    server_ = make("server");
    client_ = make("client");
    stranger_ = make("stranger");
    endpoint_ = "tcp://127.0.0.1:" + std::to_string(testing::free_tcp_port());
  }
  SocketOptions server_options(bool curve = true) const {
    SocketOptions options;
    options.linger_ms = 0;
    if (curve) options.curve = load_curve_keys(server_, {client_}, true);
    return options;
  }
  SocketOptions client_options(const std::string& server_key, const std::string& client) const {
    SocketOptions options;
    options.linger_ms = 0;
    options.curve = load_curve_keys(server_key, {client}, false);
    return options;
  }
  // An edge (consumer binds, producer connects) with the producer's options; the messages that
  // arrived within 1.5 s and the server context's refusals.
  std::pair<int, std::uint64_t> edge(const SocketOptions& producer) {
    TransportContext server_context, client_context;  // two ends as in two processes
    Receiver receiver(server_context, endpoint_, server_options());
    Sender sender(client_context, endpoint_, Sender::Pattern::edge, producer);
    for (std::uint64_t i = 0; i < 5; ++i) sender.send(numbered(i), [] { return true; });
    const int received = count_received(receiver, 1500ms);
    return {received, server_context.refused_connections()};
  }
  std::string server_, client_, stranger_, endpoint_;
};

TEST_F(CurveSockets, TheListedClientGetsThroughOnAnEdge) {
  TransportContext server_context, client_context;
  Receiver receiver(server_context, endpoint_, server_options());
  Sender sender(client_context, endpoint_, Sender::Pattern::edge, client_options(server_, client_));
  for (std::uint64_t i = 0; i < 5; ++i) ASSERT_TRUE(sender.send(numbered(i)));
  for (std::uint64_t i = 0; i < 5; ++i) {
    std::optional<wire::Decoded> got;
    for (int attempt = 0; attempt < 100 && !got; ++attempt) got = receiver.receive(100ms).message;
    ASSERT_TRUE(got) << "message " << i;
    EXPECT_EQ(got->packet.header().seq, i);
  }
  EXPECT_EQ(server_context.refused_connections(), 0u);
}

TEST_F(CurveSockets, AClientWithoutKeysInjectsNothingAndIsLogged) {
  ::testing::internal::CaptureStderr();
  SocketOptions plain;
  plain.linger_ms = 0;
  const auto [received, refused] = edge(plain);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(received, 0);
  EXPECT_GT(refused, 0u);
  // The server sees either the mismatch of mechanisms or the client leaving because of it.
  EXPECT_NE(log.find("refused a connection on " + endpoint_ + ": CURVE handshake failed ("),
            std::string::npos)
      << log;
}

TEST_F(CurveSockets, AClientWithAnUnlistedKeyInjectsNothingAndIsLoggedWithItsKey) {
  ::testing::internal::CaptureStderr();
  const auto [received, refused] = edge(client_options(server_, stranger_));
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(received, 0);
  EXPECT_GT(refused, 0u);
  const std::string key = read_public_key_file(stranger_ + ".pub");
  EXPECT_NE(log.find("client key " + key + " from 127.0.0.1 is not on the allow-list"),
            std::string::npos)
      << log;
}

TEST_F(CurveSockets, AClientWithTheWrongServerKeyInjectsNothing) {
  ::testing::internal::CaptureStderr();
  const auto [received, refused] = edge(client_options(stranger_, client_));
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(received, 0);
  EXPECT_GT(refused, 0u);
  EXPECT_NE(log.find("refused a connection on " + endpoint_ + ": CURVE handshake failed"),
            std::string::npos)
      << log;
}

TEST_F(CurveSockets, APullEndpointTakesOnlyTheListedSender) {
  // source.remote_keypoints binds a PULL socket; senders PUSH (here raw ZeroMQ, like Python).
  TransportContext server_context;
  Receiver receiver(server_context, endpoint_, server_options(), Receiver::Pattern::pull_bind);
  const auto push = [&](const std::string& client) {
    zmq::context_t context;
    zmq::socket_t socket(context, zmq::socket_type::push);
    socket.set(zmq::sockopt::linger, 0);
    if (!client.empty()) {
      const std::string secret = read_secret_key_file(client + ".key");
      socket.set(zmq::sockopt::curve_serverkey, read_public_key_file(server_ + ".pub"));
      socket.set(zmq::sockopt::curve_publickey, curve_public_key(secret));
      socket.set(zmq::sockopt::curve_secretkey, secret);
    }
    socket.connect(endpoint_);
    const std::vector<wire::Frame> frames = wire::encode(numbered(7), 0);
    for (std::size_t i = 0; i < frames.size(); ++i) {
      socket.send(zmq::buffer(frames[i].data, frames[i].size),
                  i + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
    }
    return count_received(receiver, 1000ms);
  };
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(push(""), 0);
  EXPECT_EQ(push(stranger_), 0);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("CURVE handshake failed"), std::string::npos) << log;
  EXPECT_NE(log.find("is not on the allow-list"), std::string::npos) << log;
  EXPECT_EQ(push(client_), 1);
}

TEST_F(CurveSockets, APublishedStreamReachesOnlyTheListedSubscriber) {
  TransportContext server_context;
  SocketOptions options = server_options();
  Sender publisher(server_context, endpoint_, Sender::Pattern::publish_bind, options);
  const auto subscribe = [&](const std::string& server_key, const std::string& client) {
    zmq::context_t context;
    zmq::socket_t socket(context, zmq::socket_type::sub);
    socket.set(zmq::sockopt::linger, 0);
    socket.set(zmq::sockopt::rcvtimeo, 50);
    socket.set(zmq::sockopt::subscribe, "");
    if (!client.empty()) {
      const std::string secret = read_secret_key_file(client + ".key");
      socket.set(zmq::sockopt::curve_serverkey, read_public_key_file(server_key + ".pub"));
      socket.set(zmq::sockopt::curve_publickey, curve_public_key(secret));
      socket.set(zmq::sockopt::curve_secretkey, secret);
    }
    socket.connect(endpoint_);
    int frames = 0;
    for (int i = 0; i < 30; ++i) {  // 1.5 s of publishing
      publisher.send(numbered(static_cast<std::uint64_t>(i)));
      zmq::message_t part;
      while (socket.recv(part)) ++frames;
    }
    return frames;
  };
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(subscribe("", ""), 0);
  EXPECT_EQ(subscribe(server_, stranger_), 0);
  EXPECT_EQ(subscribe(stranger_, client_), 0);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_GE(server_context.refused_connections(), 3u);
  EXPECT_NE(log.find("refused a connection on " + endpoint_), std::string::npos) << log;
  EXPECT_GT(subscribe(server_, client_), 0);
}

TEST_F(CurveSockets, AFolderOfPublicKeysIsAnAllowList) {
  fs::create_directory(dir_.file("allowed"));
  fs::copy_file(client_ + ".pub", dir_.file("allowed/client.pub"));
  const CurveKeys keys = load_curve_keys(server_, {dir_.file("allowed")}, true);
  ASSERT_EQ(keys.allowed_clients.size(), 1u);
  EXPECT_EQ(keys.allowed_clients[0], read_public_key_file(client_ + ".pub"));
}

// --- plugins

TEST(PluginSafety, APluginOrFolderOthersCanWriteIsRefusedNamingItAndWhy) {
  TempDir dir;
  const std::string copy = dir.file("libtag_copy.so");
  fs::copy_file(MOCAP_TEST_PLUGIN, copy);
  chmod(copy.c_str(), 0755);
  EXPECT_NO_THROW(check_plugin_path_safe(copy));
  EXPECT_NO_THROW(check_plugin_path_safe(dir.path().string()));

  chmod(copy.c_str(), 0757);  // o+w
  std::string e = error_of([&] { load_plugin(copy); });
  EXPECT_NE(e.find("plugin " + copy + " is writable by others (mode 0757)"), std::string::npos)
      << e;
  e = error_of([&] { load_plugins_from(dir.path().string()); });
  EXPECT_NE(e.find("is writable by others"), std::string::npos) << e;

  chmod(copy.c_str(), 0755);
  chmod(dir.path().c_str(), 0775);  // the folder: g+w
  e = error_of([&] { load_plugin(copy); });
  EXPECT_NE(e.find("plugin folder " + dir.path().string() + " is writable by its group"),
            std::string::npos)
      << e;
  e = error_of([&] { load_plugins_from(dir.path().string()); });
  EXPECT_NE(e.find("plugin folder " + dir.path().string()), std::string::npos) << e;
  chmod(dir.path().c_str(), 0700);
  EXPECT_EQ(dlopen(copy.c_str(), RTLD_NOW | RTLD_NOLOAD), nullptr);  // never loaded
}

TEST(PluginSafety, AGraphListingAWritablePluginFailsValidationWithItsLine) {
  TempDir dir;
  const std::string copy = dir.file("libtag_copy.so");
  fs::copy_file(MOCAP_TEST_PLUGIN, copy);
  chmod(copy.c_str(), 0666);
  testing::write_file(
      dir.file("g.yaml"),
      "plugins: [libtag_copy.so]\nnodes:\n  src: { type: test.counter, params: { count: 1 } }\n");
  const std::string e = error_of([&] { resolve(load_graph_file(dir.file("g.yaml"))); });
  EXPECT_NE(e.find("g.yaml:1: plugin " + copy + " is writable by"), std::string::npos) << e;
}

}  // namespace
}  // namespace mocap::graph
