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
  EXPECT_NE(message.find("g.yaml:2: node 'a': parameter 'count' takes a single int, not a list"),
            std::string::npos)
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
  const ParamSpec number{
      .name = "beta", .type = ParamType::number, .fallback = 0.4, .range = {0.0, 10.0}};
  EXPECT_EQ(std::get<double>(parse_param(number, "2.5")), 2.5);
  EXPECT_THROW(parse_param(number, "11"), std::invalid_argument);
  EXPECT_THROW(parse_param(number, "nan"), std::invalid_argument);
  EXPECT_THROW(parse_param(number, "1.0x"), std::invalid_argument);
  const ParamSpec flag{.name = "on", .type = ParamType::boolean, .fallback = false};
  EXPECT_TRUE(std::get<bool>(parse_param(flag, "yes")));
  EXPECT_FALSE(std::get<bool>(parse_param(flag, "False")));
  EXPECT_THROW(parse_param(flag, "maybe"), std::invalid_argument);
  EXPECT_EQ(parse_policy("drop_oldest(4)")->capacity, 4u);
  EXPECT_FALSE(parse_policy("blocking(0)"));
  EXPECT_FALSE(parse_policy("blocking(-1)"));
}

// A type with a choice, a list, a choice list and a repeated, joined input.
class Choosy : public Node {
 public:
  static void contract(Contract& c) {
    c.inputs<People2D>("view", "one camera", 2, 4);
    c.input<People3D>("extra", "not joined", PortFlag::optional);
    c.output<People2D>("out");
    c.join({{"view"}, SyncKey::capture_time, 32, 5.0, 100.0});
    c.param_choice("mode", "live", {"live", "full", "off"}, "how");
    c.param_list<double>("weights", {1.0, 2.0}, "per view", {0.0, 10.0});
    c.param_choice_list("joints", {"head"}, {"head", "neck", "root"}, "which");
  }
  void process(Context&) override {}
};
MOCAP_REGISTER_NODE("unit.choosy", Choosy)

std::string choosy(const std::string& params, const std::string& edges) {
  return "nodes:\n  a: { type: test.counter }\n  b: { type: test.counter }\n"
         "  c: { type: test.counter }\n  x: { type: unit.choosy" +
         (params.empty() ? "" : ", params: " + params) + " }\nedges:\n" + edges;
}
const std::string kTwoViews = "  - [a.out, x.view:0]\n  - [b.out, x.view:1]\n";

TEST(GraphFile, RepeatedInputsAreWiredByIndexWithoutGaps) {
  TempDir dir;
  testing::write_file(dir.file("g.yaml"),
                      choosy("", "  - [b.out, x.view:1]\n  - [a.out, x.view:0]\n"));
  const ResolvedGraph graph = resolve(load_graph_file(dir.file("g.yaml")));
  EXPECT_EQ(graph.find("x")->input_counts, (std::vector<std::size_t>{2, 0}));
  EXPECT_NE(to_dot(graph).find("out -> view:1"), std::string::npos) << to_dot(graph);

  std::string message = problems(choosy("", "  - [a.out, x.view:0]\n  - [b.out, x.view:2]\n"));
  EXPECT_NE(message.find("g.yaml:8: input x.view:1 is not connected, but x.view:2 is"),
            std::string::npos)
      << message;
  message = problems(choosy("", "  - [a.out, x.view]\n  - [b.out, x.view:1]\n"));
  EXPECT_NE(message.find("g.yaml:7: edge a.out -> x.view: x.view is a repeated input: wire each "
                         "edge to an index, x.view:0"),
            std::string::npos)
      << message;
  message = problems(choosy("", "  - [a.out, x.view:0]\n"));
  EXPECT_NE(message.find("g.yaml:7: input x.view takes 2 to 4 edges (x.view:0..3), not 1"),
            std::string::npos)
      << message;
  message = problems(choosy("", kTwoViews + "  - [c.out, x.view:1]\n"));
  EXPECT_NE(message.find("g.yaml:9: input x.view:1 is already fed by the edge at g.yaml:8"),
            std::string::npos)
      << message;
  message = problems(
      "nodes:\n  a: { type: test.counter }\n  p: { type: flow.pass_through }\n"
      "edges:\n  - [a.out, p.in:0]\n");
  EXPECT_NE(message.find("g.yaml:5: edge a.out -> p.in:0: input p.in takes one edge, without an "
                         "index"),
            std::string::npos)
      << message;
  message = problems(
      "nodes:\n  a: { type: test.counter }\n  p: { type: flow.pass_through }\n"
      "edges:\n  - [a.out:1, p.in]\n");
  EXPECT_NE(message.find("g.yaml:5: edge a.out:1 -> p.in: an output takes no index"),
            std::string::npos)
      << message;
  message = problems("nodes:\n  a: { type: test.counter }\nedges:\n  - [a.out, b.in:x]\n");
  EXPECT_NE(message.find("g.yaml:4: edge end 'b.in:x' must be written node.port"),
            std::string::npos)
      << message;
}

TEST(GraphFile, ChoicesAreCheckedWithTheAllowedValuesAndANearMiss) {
  EXPECT_EQ(problems(choosy("{ mode: full }", kTwoViews)), "");
  std::string message = problems(choosy("{ mode: fulll }", kTwoViews));
  EXPECT_NE(message.find("g.yaml:5: node 'x': parameter 'mode': 'fulll' is not one of live, full, "
                         "off; did you mean 'full'?"),
            std::string::npos)
      << message;
  message = problems(choosy("{ mode: sideways }", kTwoViews));
  EXPECT_NE(message.find("'sideways' is not one of live, full, off"), std::string::npos) << message;
  EXPECT_EQ(message.find("did you mean"), std::string::npos) << message;
  message = problems(choosy("", kTwoViews), {"x.mode=Live"});
  EXPECT_NE(message.find("--set x.mode=Live: node 'x': parameter 'mode': 'Live' is not one of "
                         "live, full, off; did you mean 'live'?"),
            std::string::npos)
      << message;
  // The synchroniser's parameters are checked the same way.
  message = problems(choosy("{ sync_by: frames }", kTwoViews));
  EXPECT_NE(message.find("did you mean 'frame'?"), std::string::npos) << message;
  // Names too: an unknown parameter or type close to a known one.
  message = problems(choosy("{ mdoe: full }", kTwoViews));
  EXPECT_NE(message.find("has no parameter 'mdoe'; did you mean 'mode'?"), std::string::npos)
      << message;
  message = problems("nodes:\n  a: { type: test.countr }\n");
  EXPECT_NE(message.find("unknown node type 'test.countr' (did you mean 'test.counter'?"),
            std::string::npos)
      << message;
}

TEST(GraphFile, ListsAreYamlSequencesOrCommaListsWithEachItemChecked) {
  TempDir dir;
  testing::write_file(dir.file("g.yaml"),
                      choosy("{ weights: [0.5, 3], joints: [neck, root] }", kTwoViews));
  GraphSpec spec = load_graph_file(dir.file("g.yaml"));
  ResolvedGraph graph = resolve(spec);
  EXPECT_EQ(std::get<std::vector<double>>(graph.find("x")->params.at("weights")),
            (std::vector<double>{0.5, 3.0}));
  EXPECT_EQ(std::get<std::vector<std::string>>(graph.find("x")->params.at("joints")),
            (std::vector<std::string>{"neck", "root"}));
  apply_overrides(spec, {"x.weights=1, 2,4", "x.joints="});
  graph = resolve(spec);
  EXPECT_EQ(std::get<std::vector<double>>(graph.find("x")->params.at("weights")),
            (std::vector<double>{1.0, 2.0, 4.0}));
  EXPECT_TRUE(std::get<std::vector<std::string>>(graph.find("x")->params.at("joints")).empty());

  std::string message = problems(choosy("{ weights: [1, 20] }", kTwoViews));
  EXPECT_NE(message.find("g.yaml:5: node 'x': parameter 'weights': expected a value in [0"),
            std::string::npos)
      << message;
  message = problems(choosy("{ joints: [head, nek] }", kTwoViews));
  EXPECT_NE(message.find("'nek' is not one of head, neck, root; did you mean 'neck'?"),
            std::string::npos)
      << message;
  message = problems(choosy("{ mode: [live, off] }", kTwoViews));
  EXPECT_NE(
      message.find("g.yaml:5: node 'x': parameter 'mode' takes a single choice of live, full, "
                   "off, not a list"),
      std::string::npos)
      << message;
  message = problems(choosy("{ weights: [1, [2]] }", kTwoViews));
  EXPECT_NE(message.find("g.yaml:5:"), std::string::npos) << message;
}

TEST(Registry, InspectShowsRepeatedInputsJoinsChoicesAndLists) {
  const std::string text = describe(*Registry::instance().find("unit.choosy"));
  EXPECT_NE(text.find("view:0..N : People2D (2 to 4 edges) (joined)"), std::string::npos) << text;
  EXPECT_NE(text.find("joined: view, one set per capture time"), std::string::npos) << text;
  EXPECT_NE(text.find("mode : choice of live, full, off = live"), std::string::npos) << text;
  EXPECT_NE(text.find("weights : list of number = 1,2 in [0"), std::string::npos) << text;
  EXPECT_NE(text.find("sync_tolerance_ms : number = 5"), std::string::npos) << text;
  EXPECT_NE(text.find("sync_by : choice of frame, capture_time = capture_time"), std::string::npos)
      << text;
  Contract c;
  c.input_any("a");
  EXPECT_THROW(c.join({{"b"}}), std::logic_error);
  EXPECT_THROW(c.param_choice("m", "x", {"a", "b"}, "a default outside its choices"),
               std::invalid_argument);
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
