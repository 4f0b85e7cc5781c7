// CURVE in real processes (docs/security.md): `mocap keys generate`, a two-process graph whose tcp
// edge has keys under the `mocap run` supervisor, a producer whose key the consumer does not list
// (nothing arrives, the consumer logs it), the Python sender with and without keys against
// source.remote_keypoints, and validation refusing a plain network edge.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <regex>

#include "graph_test_util.hpp"
#include "support/mocap_process.hpp"

namespace mocap::graph {
namespace {

using namespace std::chrono_literals;
using test::ChildProcess;
using test::Mocap;
using testing::TempDir;

mode_t mode_of(const std::string& path) {
  struct stat info {};
  stat(path.c_str(), &info);
  return info.st_mode & 07777;
}

// Makes DIR/keys/NAME.key and .pub with the real command.
void generate(const TempDir& dir, const std::string& name) {
  Mocap keys(dir, "keys-" + name, {"keys", "generate", name, "--dir", dir.file("keys")});
  ASSERT_EQ(keys.wait(30s), 0) << keys.err();
}

TEST(SecurityProcess, KeysGenerateWritesThePairAndRefusesToOverwrite) {
  TempDir dir;
  Mocap first(dir, "first", {"keys", "generate", "solve", "--dir", dir.file("keys")});
  ASSERT_EQ(first.wait(30s), 0) << first.err();
  EXPECT_EQ(mode_of(dir.file("keys/solve.key")), 0600u);
  EXPECT_EQ(mode_of(dir.file("keys")), 0700u);
  const std::string secret = testing::read_file(dir.file("keys/solve.key"));
  const std::string pub = testing::read_file(dir.file("keys/solve.pub"));
  EXPECT_NE(first.out().find(dir.file("keys/solve.pub")), std::string::npos) << first.out();

  Mocap again(dir, "again", {"keys", "generate", "solve", "--dir", dir.file("keys")});
  EXPECT_EQ(again.wait(30s), 1);
  EXPECT_NE(again.err().find("solve.key exists; pass --force"), std::string::npos) << again.err();
  EXPECT_EQ(testing::read_file(dir.file("keys/solve.key")), secret);

  Mocap forced(dir, "forced", {"keys", "generate", "solve", "--dir", dir.file("keys"), "--force"});
  EXPECT_EQ(forced.wait(30s), 0) << forced.err();
  EXPECT_NE(testing::read_file(dir.file("keys/solve.pub")), pub);

  // Without --dir: $MOCAP_KEY_DIR (else ~/.config/mocap/keys).
  Mocap by_env(dir, "env", {"keys", "generate", "viewer"}, {"MOCAP_KEY_DIR=" + dir.file("env")});
  EXPECT_EQ(by_env.wait(30s), 0) << by_env.err();
  EXPECT_EQ(mode_of(dir.file("env/viewer.key")), 0600u);
}

// A counter in process `capture`, a collector in `solve`, joined by a tcp edge with CURVE.
std::string curve_graph(const TempDir& dir, const std::string& endpoint, int count) {
  return "graph: curve\nallow_network: true\nnodes:\n"
         "  src:  { type: test.counter, params: { count: " +
         std::to_string(count) +
         ", interval_ms: 2 } }\n"
         "  sink: { type: test.collect, params: { path: " +
         dir.file("sink.txt") +
         " } }\n"
         "edges:\n"
         "  - [src.out, sink.in, { transport: \"" +
         endpoint +
         "\", curve: { server: keys/solve, client: keys/capture } }]\n"
         "processes:\n  capture: [src]\n  solve: [sink]\n";
}

TEST(SecurityProcess, TwoProcessGraphWithACurveTcpEdgeRunsEndToEnd) {
  TempDir dir;
  generate(dir, "solve");
  generate(dir, "capture");
  const std::string endpoint = "tcp://127.0.0.1:" + std::to_string(testing::free_tcp_port());
  testing::write_file(dir.file("g.yaml"), curve_graph(dir, endpoint, 200));
  Mocap run(dir, "run", {"run", dir.file("g.yaml")});
  ASSERT_EQ(run.wait(60s), 0) << run.err();
  const auto lines = testing::read_lines(dir.file("sink.txt"));
  ASSERT_EQ(lines.size(), 200u) << run.err();
  for (std::size_t i = 0; i < lines.size(); ++i) {
    ASSERT_EQ(testing::fields(lines[i])[1], std::to_string(i)) << "line " << i;
  }
  EXPECT_EQ(run.err().find("refused"), std::string::npos) << run.err();
}

TEST(SecurityProcess, AProducerWhoseKeyTheConsumerDoesNotListInjectsNothing) {
  TempDir dir;
  generate(dir, "solve");
  generate(dir, "capture");
  generate(dir, "stranger");
  const std::string endpoint = "tcp://127.0.0.1:" + std::to_string(testing::free_tcp_port());
  testing::write_file(dir.file("g.yaml"), curve_graph(dir, endpoint, 50));
  // The producer's host holds another secret key under the expected name: an impostor.
  std::filesystem::copy_file(dir.file("keys/stranger.key"), dir.file("keys/capture.key"),
                             std::filesystem::copy_options::overwrite_existing);
  Mocap solve(dir, "solve", {"run", dir.file("g.yaml"), "--process", "solve"});
  Mocap capture(dir, "capture", {"run", dir.file("g.yaml"), "--process", "capture"});
  const auto refused = solve.wait_for_log("refused a connection on " + endpoint +
                                              ": client key (\\S+) from 127\\.0\\.0\\.1 is not "
                                              "on the allow-list",
                                          20s);
  ASSERT_TRUE(refused) << solve.err();
  EXPECT_NE(testing::read_file(dir.file("keys/stranger.pub")).find(*refused), std::string::npos);
  EXPECT_TRUE(capture.wait_for_log(
      "connection to " + endpoint + " refused: the server does not accept this client's key", 10s))
      << capture.err();
  std::this_thread::sleep_for(500ms);
  EXPECT_TRUE(testing::read_lines(dir.file("sink.txt")).empty());
  ASSERT_TRUE(solve.wait_until_blocking(SIGTERM, 5s));
  kill(solve.pid(), SIGTERM);
  EXPECT_TRUE(solve.wait(20s));
  EXPECT_TRUE(testing::read_lines(dir.file("sink.txt")).empty());
}

TEST(SecurityProcess, ValidationRefusesAPlainNetworkEdgeAndAPastedKey) {
  TempDir dir;
  const std::string graph = dir.file("g.yaml");
  testing::write_file(graph,
                      "allow_network: true\nnodes:\n"
                      "  src: { type: test.counter, params: { count: 3 } }\n"
                      "  sink: { type: test.collect, params: { path: /dev/null } }\n"
                      "edges:\n  - [src.out, sink.in, { transport: \"tcp://0.0.0.0:5791\" }]\n"
                      "processes:\n  a: [src]\n  b: [sink]\n");
  Mocap plain(dir, "plain", {"run", graph});
  ASSERT_EQ(plain.wait(30s), 1);
  EXPECT_NE(plain.err().find(graph + ":6: edge src.out -> sink.in crosses the network (0.0.0.0) "
                                     "without keys"),
            std::string::npos)
      << plain.err();
  testing::write_file(graph,
                      "nodes:\n"
                      "  src: { type: test.counter, params: { count: 3 } }\n"
                      "  pub: { type: sink.publish, params: { endpoint: \"tcp://127.0.0.1:5560\", "
                      "curve_server: \"rq:rM>}U?@Lns47E1%kR.o@n%FcmmsL/@{H8]yf7\", curve_client: "
                      "x } }\nedges:\n  - [src.out, pub.in]\n");
  Mocap pasted(dir, "pasted", {"graph", "validate", graph});
  ASSERT_EQ(pasted.wait(30s), 1);
  EXPECT_NE(pasted.err().find(graph + ":3: node 'pub': curve_server: this looks like a key itself"),
            std::string::npos)
      << pasted.err();
}

// The Python sender (tools/remote/send_keypoints.py) against source.remote_keypoints with CURVE.
TEST(SecurityProcess, OnlyThePythonSenderWithTheRightKeysFeedsRemoteKeypoints) {
  const char* folder = "../shared/data/eval/openpose_json/json";
  if (std::system((std::string(MOCAP_PYTHON3) + " -c 'import zmq' 2>/dev/null").c_str()) != 0) {
    GTEST_SKIP() << MOCAP_PYTHON3 << " cannot import zmq (apt-get install python3-zmq)";
  }
  if (!std::filesystem::is_directory(folder)) GTEST_SKIP() << folder << " is absent";
  TempDir dir;
  generate(dir, "solve");
  generate(dir, "detector");
  generate(dir, "stranger");
  const std::string endpoint = "tcp://127.0.0.1:" + std::to_string(testing::free_tcp_port());
  testing::write_file(dir.file("g.yaml"),
                      "nodes:\n"
                      "  remote: { type: source.remote_keypoints, params: { endpoint: \"" +
                          endpoint +
                          "\", timeout_ms: 60000, curve_server: keys/solve, curve_client: "
                          "keys/detector } }\n"
                          "  collect: { type: test.collect, params: { path: \"" +
                          dir.file("got.txt") +
                          "\" } }\n"
                          "edges:\n  - [remote.out, collect.in]\n");
  Mocap run(dir, "run", {"run", dir.file("g.yaml")});
  ASSERT_TRUE(run.wait_for_log("receiving keypoints on", 30s)) << run.err();
  const auto python = [&](const std::string& name, std::vector<std::string> keys) {
    std::vector<std::string> args = {"tools/remote/send_keypoints.py",
                                     folder,
                                     "--endpoint",
                                     endpoint,
                                     "--limit",
                                     "20",
                                     "--linger-ms",
                                     "3000"};
    args.insert(args.end(), keys.begin(), keys.end());
    return std::make_unique<ChildProcess>(MOCAP_PYTHON3, args, "/dev/null", dir.file(name + ".err"),
                                          test::environment());
  };
  // No keys, then a key the node does not list: nothing of theirs arrives (not even their
  // EndOfStream, which would end the graph), and the node's process logs both.
  auto plain = python("plain", {});
  ASSERT_TRUE(run.wait_for_log("CURVE handshake failed", 20s)) << run.err();
  plain->wait(10s);
  auto stranger = python("stranger", {"--server-key", dir.file("keys/solve.pub"), "--client-key",
                                      dir.file("keys/stranger.key")});
  ASSERT_TRUE(run.wait_for_log("is not on the allow-list", 20s)) << run.err();
  stranger->wait(10s);
  EXPECT_TRUE(testing::read_lines(dir.file("got.txt")).empty());
  // A secret key file others can read is refused by the sender itself.
  chmod(dir.file("keys/detector.key").c_str(), 0644);
  auto careless = python("careless", {"--server-key", dir.file("keys/solve.pub"), "--client-key",
                                      dir.file("keys/detector.key")});
  EXPECT_EQ(careless->wait(20s), 1);
  EXPECT_NE(careless->err().find("open to group or others"), std::string::npos) << careless->err();
  chmod(dir.file("keys/detector.key").c_str(), 0600);

  auto good = python("good", {"--server-key", dir.file("keys/solve.pub"), "--client-key",
                              dir.file("keys/detector.key")});
  ASSERT_EQ(good->wait(60s), 0) << good->err();
  ASSERT_EQ(run.wait(60s), 0) << run.err();
  EXPECT_EQ(testing::read_lines(dir.file("got.txt")).size(), 20u) << run.err();
  EXPECT_NE(run.err().find("20 People2D received, 0 rejected"), std::string::npos) << run.err();
}

}  // namespace
}  // namespace mocap::graph
