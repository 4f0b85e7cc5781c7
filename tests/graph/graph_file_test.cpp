// Graph files: every malformed case is rejected, and the message names the file and the line.

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "graph/validation.hpp"
#include "graph_test_util.hpp"

namespace mocap::graph {
namespace {

using testing::TempDir;

// A typed input, so that type mismatches can be written.
class PeopleOnly : public Node {
 public:
  static void contract(Contract& c) {
    c.input<People2D>("in");
    c.param<std::int64_t>("k", 4, "a bounded integer", {1, 64});
  }
  void process(Context&) override {}
};
MOCAP_REGISTER_NODE("unit.people_only", PeopleOnly)

// Loads and validates `text` written to a file; returns the error message, or "" when valid.
std::string problems(const std::string& text, std::vector<std::string> overrides = {}) {
  TempDir dir;
  const std::string path = dir.file("g.yaml");
  testing::write_file(path, text);
  try {
    GraphSpec spec = load_graph_file(path);
    apply_overrides(spec, overrides);
    resolve(std::move(spec));
    return "";
  } catch (const InputError& e) {
    std::string message = e.what();
    // Report positions relative to the file name so expectations stay readable.
    for (std::size_t at; (at = message.find(path)) != std::string::npos;)
      message.replace(at, path.size(), "g.yaml");
    return message;
  }
}

const std::string kValid = R"(graph: ok
nodes:
  src:  { type: test.counter, params: { count: 5 } }
  pass: { type: flow.pass_through }
  sink: { type: test.collect, params: { path: /tmp/unused } }
edges:
  - [src.out, pass.in, { policy: blocking(4) }]
  - { from: pass.out, to: sink.in, policy: latest }
)";

TEST(GraphFile, ValidGraphResolvesWithTypesAndPolicies) {
  TempDir dir;
  testing::write_file(dir.file("g.yaml"), kValid);
  const ResolvedGraph graph = resolve(load_graph_file(dir.file("g.yaml")));
  ASSERT_EQ(graph.nodes.size(), 3u);
  EXPECT_EQ(graph.nodes[0].name, "src");                       // topological order
  EXPECT_EQ(graph.find("pass")->output_types[0], "People2D");  // same_as resolved
  EXPECT_EQ(graph.spec.edges[0].policy.capacity, 4u);
  EXPECT_EQ(graph.spec.edges[1].policy.kind, PolicyKind::latest);
  EXPECT_EQ(std::get<std::int64_t>(graph.find("src")->params.at("count")), 5);
  EXPECT_NE(to_dot(graph).find("\"src\" -> \"pass\""), std::string::npos);
}

TEST(GraphFile, BadYamlNamesTheLine) {
  EXPECT_NE(problems("graph: x\nnodes:\n  a: { type: test.counter\n  b: [\n").find("g.yaml:"),
            std::string::npos);
  const std::string message = problems("graph: x\nnodes:\n  a: {type: test.counter}\n   b: oops\n");
  EXPECT_NE(message.find("g.yaml:4"), std::string::npos) << message;
}

TEST(GraphFile, UnknownNodeType) {
  const std::string message =
      problems("nodes:\n  a: { type: test.counter }\n  b: { type: no.such_type }\n");
  EXPECT_NE(message.find("g.yaml:3: node 'b': unknown node type 'no.such_type'"), std::string::npos)
      << message;
}

TEST(GraphFile, UnknownPorts) {
  std::string message = problems(
      "nodes:\n  a: { type: test.counter }\n  b: { type: flow.pass_through }\n"
      "  c: { type: test.collect, params: { path: x } }\nedges:\n  - [a.nope, b.in]\n  - [b.out, "
      "c.in]\n");
  EXPECT_NE(
      message.find("g.yaml:6: edge a.nope -> b.in: node 'a' (test.counter) has no output 'nope'"),
      std::string::npos)
      << message;
  message = problems(
      "nodes:\n  a: { type: test.counter }\n  c: { type: test.collect, params: { path: x } }\n"
      "edges:\n  - [a.out, c.in]\n  - [a.out, c.wrong]\n");
  EXPECT_NE(message.find("g.yaml:6:"), std::string::npos) << message;
  EXPECT_NE(message.find("has no input 'wrong'"), std::string::npos) << message;
  message = problems("nodes:\n  a: { type: test.counter }\nedges:\n  - [a.out, ghost.in]\n");
  EXPECT_NE(message.find("g.yaml:4: edge a.out -> ghost.in: no node 'ghost'"), std::string::npos)
      << message;
}

TEST(GraphFile, TypeMismatch) {
  // frames -> pass_through (any, so it carries VideoFrame) -> a People2D input.
  const std::string message = problems(
      "nodes:\n  cam: { type: test.frames }\n  p: { type: flow.pass_through }\n"
      "  u: { type: unit.people_only }\nedges:\n  - [cam.frames, p.in]\n  - [p.out, u.in]\n");
  EXPECT_NE(message.find("g.yaml:7: edge p.out -> u.in: type mismatch, p.out sends VideoFrame but "
                         "u.in takes People2D"),
            std::string::npos)
      << message;
}

TEST(GraphFile, ParameterProblems) {
  std::string message = problems(
      "nodes:\n  s: { type: test.collect }\n  a: { type: test.counter }\nedges:\n  - [a.out, "
      "s.in]\n");
  EXPECT_NE(message.find("g.yaml:2: node 's' (test.collect) needs parameter 'path'"),
            std::string::npos)
      << message;
  message = problems(
      "nodes:\n  a:\n    type: test.counter\n    params:\n      count: 5\n      colour: red\n");
  EXPECT_NE(message.find("g.yaml:6: node 'a' (test.counter) has no parameter 'colour'"),
            std::string::npos)
      << message;
  message = problems("nodes:\n  a:\n    type: test.counter\n    params:\n      count: lots\n");
  EXPECT_NE(
      message.find("g.yaml:5: node 'a': parameter 'count': expected a whole number, got 'lots'"),
      std::string::npos)
      << message;
  message = problems("nodes:\n  a: { type: test.counter, params: { people: 65 } }\n");
  EXPECT_NE(message.find("g.yaml:2: node 'a': parameter 'people': expected a value in [0"),
            std::string::npos)
      << message;
  message = problems("nodes:\n  a: { type: test.counter, params: { count: [1, 2] } }\n");
  EXPECT_NE(message.find("g.yaml:2: parameter 'count' must be a single value"), std::string::npos)
      << message;
}

TEST(GraphFile, OverridesAreCheckedLikeTheFile) {
  EXPECT_EQ(problems(kValid, {"src.count=7"}), "");
  EXPECT_NE(
      problems(kValid, {"src.count=-1"}).find("--set src.count=-1: node 'src': parameter 'count'"),
      std::string::npos);
  EXPECT_NE(problems(kValid, {"ghost.count=1"}).find("no node 'ghost'"), std::string::npos);
  EXPECT_NE(problems(kValid, {"srccount1"}).find("expected node.param=value"), std::string::npos);
}

TEST(GraphFile, Cycle) {
  const std::string message = problems(
      "nodes:\n  a: { type: flow.pass_through }\n  b: { type: flow.pass_through }\n"
      "edges:\n  - [a.out, b.in]\n  - [b.out, a.in]\n");
  EXPECT_NE(message.find("closes a cycle"), std::string::npos) << message;
  EXPECT_NE(message.find("g.yaml:5:"), std::string::npos) << message;
}

TEST(GraphFile, EdgeProblems) {
  std::string message = problems(
      "nodes:\n  a: { type: test.counter }\n  s: { type: test.collect, params: { path: x } }\n"
      "edges:\n  - [a.out, s.in, { policy: sometimes }]\n");
  EXPECT_NE(message.find("g.yaml:5: unknown edge policy 'sometimes'"), std::string::npos)
      << message;
  message = problems(
      "nodes:\n  a: { type: test.counter }\n  s: { type: test.collect, params: { path: x } }\n"
      "edges:\n  - [a.out, s.in, { policy: \"latest(3)\" }]\n");
  EXPECT_NE(message.find("g.yaml:5: unknown edge policy"), std::string::npos) << message;
  message = problems(
      "nodes:\n  a: { type: test.counter }\n  b: { type: test.counter }\n  s: { type: "
      "test.collect, params: { path: x } }\n"
      "edges:\n  - [a.out, s.in]\n  - [b.out, s.in]\n");
  EXPECT_NE(message.find("g.yaml:7: input s.in is already fed by the edge at"), std::string::npos)
      << message;
  message = problems(
      "nodes:\n  a: { type: test.counter }\n  s: { type: test.collect, params: { path: x } }\n");
  EXPECT_NE(message.find("g.yaml:3: input s.in is not connected"), std::string::npos) << message;
  message = problems(
      "nodes:\n  a: { type: test.counter }\n  s: { type: test.collect, params: { path: x } }\n"
      "edges:\n  - [a.out, s.in, { transport: \"http://x\" }]\n");
  EXPECT_NE(message.find("g.yaml:5: transport 'http://x' must be"), std::string::npos) << message;
  message = problems(
      "nodes:\n  a: { type: test.counter }\n  s: { type: test.collect, params: { path: x } }\n"
      "edges:\n  - [a.out, s.in, { transport: \"tcp://0.0.0.0:5555\" }]\n");
  EXPECT_NE(message.find("g.yaml:5:"), std::string::npos) << message;
  EXPECT_NE(message.find("allow_network: true"), std::string::npos) << message;
  // The viewer's page has no authentication: beyond loopback only when the graph allows it.
  message = problems("nodes:\n  v: { type: sink.web, params: { host: 0.0.0.0 } }\n");
  EXPECT_NE(message.find("g.yaml:2: node 'v': host 0.0.0.0 serves the page beyond this machine"),
            std::string::npos)
      << message;
  message =
      problems("allow_network: true\nnodes:\n  v: { type: sink.web, params: { host: 0.0.0.0 } }\n");
  EXPECT_EQ(message.find("without authentication"), std::string::npos) << message;
  message = problems("nodes:\n  v: { type: sink.web, params: { host: 127.0.0.1 } }\n");
  EXPECT_EQ(message.find("without authentication"), std::string::npos) << message;
  message = problems("nodes:\n  a: { type: test.counter }\nedges:\n  - [a, b]\n");
  EXPECT_NE(message.find("g.yaml:4: edge end 'a' must be written node.port"), std::string::npos)
      << message;
}

TEST(GraphFile, PlacementProblems) {
  const std::string graph =
      "nodes:\n  a: { type: test.counter }\n  s: { type: test.collect, params: { path: x } }\n"
      "edges:\n  - [a.out, s.in]\nprocesses:\n  one: [a]\n  two: [s]\n";
  std::string message = problems(graph);
  EXPECT_NE(message.find("g.yaml:5: edge a.out -> s.in crosses from process 'one' to 'two'"),
            std::string::npos)
      << message;
  message = problems(
      "nodes:\n  a: { type: test.counter }\n  s: { type: test.collect, params: { path: x } }\n"
      "edges:\n  - [a.out, s.in]\nprocesses:\n  one: [a]\n");
  EXPECT_NE(message.find("g.yaml:3: node 's' is not placed in any process"), std::string::npos)
      << message;
  message =
      problems("nodes:\n  a: { type: test.counter }\nprocesses:\n  one: [a]\n  two: [a, z]\n");
  EXPECT_NE(message.find("g.yaml:5: process 'two': no node 'z'"), std::string::npos) << message;
  EXPECT_NE(message.find("placed in both"), std::string::npos) << message;
}

TEST(GraphFile, StructureProblems) {
  EXPECT_NE(problems("graph: x\n").find("g.yaml:1: the graph has no nodes:"), std::string::npos);
  EXPECT_NE(problems("nodes:\n  a: { type: test.counter }\nedgez: []\n")
                .find("g.yaml:3: unknown key 'edgez'"),
            std::string::npos);
  EXPECT_NE(problems("nodes:\n  a: { params: {} }\n").find("g.yaml:2: node 'a' has no type"),
            std::string::npos);
  EXPECT_NE(problems("nodes:\n  a: { type: test.counter, parms: {} }\n")
                .find("g.yaml:2: unknown key 'parms'"),
            std::string::npos);
  EXPECT_NE(problems("- just\n- a list\n").find("g.yaml:1:"), std::string::npos);
  // Several problems are all reported, one per line.
  const std::string many = problems("nodes:\n  a: { type: x.y }\n  b: { type: z.w }\n");
  EXPECT_NE(many.find("g.yaml:2:"), std::string::npos);
  EXPECT_NE(many.find("\n"), std::string::npos);
  EXPECT_NE(many.find("g.yaml:3:"), std::string::npos);
}

TEST(GraphFile, MissingFile) {
  EXPECT_THROW(load_graph_file("/nonexistent/graph.yaml"), InputError);
}

TEST(Params, ParsingAndRanges) {
  const ParamSpec number{"beta", ParamType::number, 0.4, {0.0, 10.0}, "doc"};
  EXPECT_EQ(std::get<double>(parse_param(number, "2.5")), 2.5);
  EXPECT_THROW(parse_param(number, "11"), std::invalid_argument);
  EXPECT_THROW(parse_param(number, "nan"), std::invalid_argument);
  EXPECT_THROW(parse_param(number, "1.0x"), std::invalid_argument);
  const ParamSpec flag{"on", ParamType::boolean, false, {}, "doc"};
  EXPECT_TRUE(std::get<bool>(parse_param(flag, "yes")));
  EXPECT_FALSE(std::get<bool>(parse_param(flag, "False")));
  EXPECT_THROW(parse_param(flag, "maybe"), std::invalid_argument);
  EXPECT_EQ(parse_policy("drop_oldest(4)")->capacity, 4u);
  EXPECT_FALSE(parse_policy("blocking(0)"));
  EXPECT_FALSE(parse_policy("blocking(-1)"));
}

TEST(Registry, ContractsAndInspect) {
  const NodeType* counter = Registry::instance().find("test.counter");
  ASSERT_NE(counter, nullptr);
  EXPECT_TRUE(counter->contract.is_source());
  EXPECT_EQ(counter->contract.outputs()[0].type, "People2D");
  const std::string text = describe(*counter);
  EXPECT_NE(text.find("count : int = 100 in [0"), std::string::npos) << text;
  EXPECT_NE(text.find("out : People2D"), std::string::npos) << text;
  // A second registration under a taken name is refused and reported, not fatal.
  EXPECT_FALSE(register_node<PeopleOnly>("test.counter"));
  EXPECT_FALSE(Registry::instance().problems().empty());
  Contract c;
  c.input_any("in");
  EXPECT_THROW(c.input_any("in"), std::logic_error);
  EXPECT_THROW(c.output_same_as("out", "nope"), std::logic_error);
  EXPECT_THROW(c.param<int>("p", 50, "out of its own range", {0, 10}), std::invalid_argument);
}

}  // namespace
}  // namespace mocap::graph
