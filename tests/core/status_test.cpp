#include "gvkit/core/status.hpp"

#include <gtest/gtest.h>

namespace gvkit {
namespace {

Result<int> parse_positive(int x) {
  if (x <= 0) return invalid_argument("value must be positive, is " + std::to_string(x));
  return x;
}

Result<int> doubled(int x) {
  GVKIT_ASSIGN_OR_RETURN(int v, parse_positive(x));
  return 2 * v;
}

Status check_both(int a, int b) {
  GVKIT_RETURN_IF_ERROR(parse_positive(a).status());
  GVKIT_RETURN_IF_ERROR(parse_positive(b).status());
  return Status::ok();
}

TEST(Status, OkAndErrorCarryCodeAndMessage) {
  EXPECT_TRUE(Status::ok().is_ok());
  const Status s = corrupt_data("CRC mismatch").with_context("frame 41").with_context("take3.gvid");
  EXPECT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), StatusCode::kCorruptData);
  EXPECT_EQ(s.message(), "take3.gvid: frame 41: CRC mismatch");
  EXPECT_STREQ(status_code_name(s.code()), "corrupt data");
  EXPECT_TRUE(Status::ok().with_context("x").message().empty());
}

TEST(Result, PropagatesValuesAndErrors) {
  EXPECT_EQ(*doubled(4), 8);
  const Result<int> bad = doubled(-1);
  ASSERT_FALSE(bad.is_ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(bad.status().message(), "value must be positive, is -1");
  EXPECT_TRUE(check_both(1, 2).is_ok());
  EXPECT_EQ(check_both(1, 0).message(), "value must be positive, is 0");
}

TEST(Result, ValueOfFailedResultIsAContractError) {
  const Result<int> bad = doubled(0);
  EXPECT_THROW(static_cast<void>(bad.value()), ContractError);
  EXPECT_THROW(Result<int>(Status::ok()), ContractError);
}

// A value without a move constructor (like OpenMesh meshes): copies are counted.
int g_copies = 0;
struct Counted {
  explicit Counted(int v) : value(v) {}
  Counted(const Counted& other) : value(other.value) { ++g_copies; }
  ~Counted() = default;
  int value;
};

// Built in place and returned as the only named result: never copied.
TEST(Result, InPlaceValueIsNotCopied) {
  auto make = [](bool ok) {
    Result<Counted> r(std::in_place, 7);
    if (!ok) r = Status(StatusCode::kInvalidArgument, "no");
    return r;
  };
  Result<Counted> a = make(true);
  ASSERT_TRUE(a.is_ok());
  EXPECT_EQ(a->value, 7);
  EXPECT_EQ(g_copies, 0);
  EXPECT_FALSE(make(false).is_ok());
}

TEST(Check, ThrowsContractErrorNamingTheCondition) {
  try {
    GVKIT_CHECK(1 + 1 == 3, "arithmetic");
    FAIL() << "no throw";
  } catch (const ContractError& e) {
    EXPECT_NE(std::string(e.what()).find("1 + 1 == 3"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("arithmetic"), std::string::npos);
  }
  EXPECT_NO_THROW(GVKIT_CHECK(true));
}

}  // namespace
}  // namespace gvkit
