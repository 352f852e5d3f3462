#include "frenetic/yaml/strict_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace frenetic::yaml {
namespace {

using ::testing::Eq;
using ::testing::HasSubstr;

YAML::Node Doc(const std::string& text) {
  auto root = Load(text, "f.yaml");
  EXPECT_TRUE(root.ok()) << root.message();
  return root.ok() ? *root : YAML::Node();
}

TEST(StrictReaderTest, SyntaxErrorNamesFileAndLine) {
  auto root = Load("a: 1\nb: [1, 2\n", "broken.yaml");
  ASSERT_FALSE(root.ok());
  EXPECT_THAT(root.message(), HasSubstr("broken.yaml: YAML error at line "));
  EXPECT_EQ(root.message().find('\n'), std::string::npos) << root.message();
}

TEST(StrictReaderTest, ReadsTypedValuesAndLeavesAbsentOnesAlone) {
  MapReader r(Doc("b: true\ni: -3\nu: 7\nd: 2.5\ns: text\nsub: {x: 1}\n"), "f.yaml");
  bool b = false;
  int i = 0;
  std::uint64_t u = 0;
  double d = 0, absent = 42;
  std::string s;
  EXPECT_TRUE(r.Read("b", &b));
  EXPECT_TRUE(r.Read("i", &i));
  EXPECT_TRUE(r.Read("u", &u));
  EXPECT_TRUE(r.Read("d", &d));
  EXPECT_TRUE(r.Read("s", &s));
  EXPECT_FALSE(r.Read("absent", &absent));
  MapReader sub = r.Sub("sub");
  int x = 0;
  EXPECT_TRUE(sub.Read("x", &x));
  sub.Finish();
  r.Finish();
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(b);
  EXPECT_EQ(i, -3);
  EXPECT_EQ(u, 7u);
  EXPECT_EQ(d, 2.5);
  EXPECT_EQ(s, "text");
  EXPECT_EQ(absent, 42);
  EXPECT_EQ(x, 1);
}

TEST(StrictReaderTest, UnknownKeyIsNamedWithItsPath) {
  MapReader r(Doc("a: 1\ntraffic: {cut_in: {rate: 1, rte: 2}}\n"), "f.yaml");
  int a = 0;
  r.Read("a", &a);
  MapReader traffic = r.Sub("traffic");
  MapReader cut_in = traffic.Sub("cut_in");
  double rate = 0;
  cut_in.Read("rate", &rate);
  cut_in.Finish();
  traffic.Finish();
  r.Finish();
  EXPECT_THAT(r.status().message(), Eq("f.yaml: unknown key 'traffic.cut_in.rte'"));
}

TEST(StrictReaderTest, UnknownTopLevelKey) {
  MapReader r(Doc("a: 1\nb: 2\n"), "f.yaml");
  int a = 0;
  r.Read("a", &a);
  r.Finish();
  EXPECT_THAT(r.status().message(), Eq("f.yaml: unknown key 'b'"));
}

TEST(StrictReaderTest, MarkedAndChildKeysAreKnownButHasIsNot) {
  MapReader r(Doc("a: 1\nb: [1]\nc: 3\n"), "f.yaml");
  EXPECT_TRUE(r.Has("a"));
  EXPECT_FALSE(r.Has("z"));
  r.MarkKnown("a");
  EXPECT_TRUE(r.Child("b").IsSequence());
  r.Finish();
  EXPECT_THAT(r.status().message(), Eq("f.yaml: unknown key 'c'"));
}

TEST(StrictReaderTest, RepeatedKeyIsAnError) {
  MapReader r(Doc("seed: 1\nseed: 2\n"), "f.yaml");
  EXPECT_THAT(r.status().message(), Eq("f.yaml: key 'seed' appears twice"));
  MapReader nested(Doc("costs: {goal: 1, goal: 2}\n"), "g.yaml");
  nested.Sub("costs");
  EXPECT_THAT(nested.status().message(), Eq("g.yaml: key 'costs.goal' appears twice"));
}

TEST(StrictReaderTest, MapsMustBeMaps) {
  MapReader top(Doc("[1, 2]\n"), "f.yaml");
  EXPECT_THAT(top.status().message(), Eq("f.yaml: expected a mapping at the top level"));
  MapReader r(Doc("limits: 3\n"), "f.yaml");
  r.Sub("limits");
  EXPECT_THAT(r.status().message(), Eq("f.yaml: 'limits' must be a mapping"));
  // An empty document or section reads as an empty map.
  MapReader empty(Doc(""), "f.yaml");
  empty.Sub("limits").Finish();
  empty.Finish();
  EXPECT_TRUE(empty.ok());
  MapReader null_section(Doc("limits:\n"), "f.yaml");
  null_section.Sub("limits").Finish();
  null_section.Finish();
  EXPECT_TRUE(null_section.ok()) << null_section.status().message();
}

struct TypeCase {
  const char* yaml;
  const char* message;
};

class StrictReaderTypeTest : public ::testing::TestWithParam<TypeCase> {};

TEST_P(StrictReaderTypeTest, WrongTypeNamesKeyTypeAndValue) {
  MapReader r(Doc(GetParam().yaml), "f.yaml");
  MapReader s = r.Sub("s");
  bool b = false;
  int i = 0;
  std::uint64_t u = 0;
  double d = 0;
  std::string text;
  s.Read("b", &b);
  s.Read("i", &i);
  s.Read("u", &u);
  s.Read("d", &d);
  s.Read("text", &text);
  EXPECT_THAT(r.status().message(), Eq(GetParam().message));
}

INSTANTIATE_TEST_SUITE_P(
    Cases, StrictReaderTypeTest,
    ::testing::Values(TypeCase{"s: {b: maybe}", "f.yaml: 's.b' must be a boolean, got 'maybe'"},
                      TypeCase{"s: {i: 1.5}", "f.yaml: 's.i' must be an integer, got '1.5'"},
                      TypeCase{"s: {d: fast}", "f.yaml: 's.d' must be a number, got 'fast'"},
                      TypeCase{"s: {d: .nan}", "f.yaml: 's.d' must be a number, got '.nan'"},
                      TypeCase{"s: {d: .inf}", "f.yaml: 's.d' must be a number, got '.inf'"},
                      TypeCase{"s: {d: [1]}", "f.yaml: 's.d' must be a number"},
                      TypeCase{"s: {d: }", "f.yaml: 's.d' must be a number"},
                      TypeCase{"s: {text: {a: 1}}", "f.yaml: 's.text' must be a string"}),
    [](const auto& info) { return "Case" + std::to_string(info.index); });

TEST(StrictReaderTest, RangeIsChecked) {
  MapReader r(Doc("grid: {speeds: 1000, ok: 16}\n"), "f.yaml");
  MapReader grid = r.Sub("grid");
  double ok = 0, speeds = 16;
  EXPECT_TRUE(grid.Read("ok", &ok, 8, 64));
  EXPECT_EQ(ok, 16);
  EXPECT_FALSE(grid.Read("speeds", &speeds, 8, 64));
  EXPECT_EQ(speeds, 16);  // unchanged
  EXPECT_THAT(r.status().message(), Eq("f.yaml: 'grid.speeds' = 1000 outside [8, 64]"));
}

TEST(StrictReaderTest, PairsAndLists) {
  MapReader r(Doc("p: [1.5, 2]\nq: [1, 3]\nl: [a, b]\nn: [1, 2]\n"), "f.yaml");
  double lo = 0, hi = 0;
  int ilo = 0, ihi = 0;
  std::vector<std::string> l;
  std::vector<std::uint64_t> n;
  EXPECT_TRUE(r.ReadPair("p", &lo, &hi));
  EXPECT_TRUE(r.ReadPair("q", &ilo, &ihi));
  EXPECT_TRUE(r.ReadList("l", &l));
  EXPECT_TRUE(r.ReadList("n", &n));
  r.Finish();
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(lo, 1.5);
  EXPECT_EQ(hi, 2);
  EXPECT_EQ(ilo, 1);
  EXPECT_EQ(ihi, 3);
  EXPECT_EQ(l, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(n, (std::vector<std::uint64_t>{1, 2}));

  const struct {
    const char* yaml;
    const char* message;
  } bad[] = {
      {"p: [1, 2, 3]", "f.yaml: 'p' must be a pair of numbers [min, max]"},
      {"p: [1, x]", "f.yaml: 'p' must be a pair of numbers [min, max]"},
      {"q: [1.5, 2]", "f.yaml: 'q' must be a pair of integers [min, max]"},
      {"l: a", "f.yaml: 'l' must be a list"},
      {"n: [1, x]", "f.yaml: 'n[1]' must be a non-negative integer"},
  };
  for (const auto& c : bad) {
    MapReader b(Doc(c.yaml), "f.yaml");
    b.ReadPair("p", &lo, &hi);
    b.ReadPair("q", &ilo, &ihi);
    b.ReadList("l", &l);
    b.ReadList("n", &n);
    EXPECT_THAT(b.status().message(), Eq(c.message)) << c.yaml;
  }
}

TEST(StrictReaderTest, KeysInDocumentOrderAndTheFirstErrorStays) {
  MapReader r(Doc("z: 1\na: x\nm: y\n"), "f.yaml");
  EXPECT_EQ(r.Keys(), (std::vector<std::string>{"z", "a", "m"}));
  double a = 0, m = 0;
  r.Read("a", &a);
  r.Read("m", &m);
  r.Fail("later", "is not reported");
  r.Finish();
  EXPECT_THAT(r.status().message(), Eq("f.yaml: 'a' must be a number, got 'x'"));
}

}  // namespace
}  // namespace frenetic::yaml
