#include "imusysid/status.h"

#include <memory>
#include <string>
#include <utility>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace imusysid {
namespace {

TEST(Status, DefaultIsOk) {
  const Status s;
  EXPECT_TRUE(s.ok());
  EXPECT_EQ(s.code(), StatusCode::kOk);
  EXPECT_EQ(s.message(), "");
  EXPECT_EQ(s.ToString(), "OK");
  EXPECT_TRUE(Status::Ok().ok());
}

TEST(Status, EachConstructorSetsItsCode) {
  EXPECT_EQ(InvalidArgumentError("m").code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(NotFoundError("m").code(), StatusCode::kNotFound);
  EXPECT_EQ(FailedPreconditionError("m").code(),
            StatusCode::kFailedPrecondition);
  EXPECT_EQ(IoError("m").code(), StatusCode::kIoError);
  EXPECT_EQ(InternalError("m").code(), StatusCode::kInternal);
  EXPECT_FALSE(InternalError("m").ok());
}

TEST(Status, ToStringNamesTheCode) {
  EXPECT_EQ(NotFoundError("no such model").ToString(),
            "NOT_FOUND: no such model");
  EXPECT_STREQ(StatusCodeToString(StatusCode::kFailedPrecondition),
               "FAILED_PRECONDITION");
  EXPECT_STREQ(StatusCodeToString(StatusCode::kIoError), "IO_ERROR");
}

TEST(Status, WithPrefixAddsContextButKeepsTheCodeAndLeavesOkAlone) {
  const Status s = InvalidArgumentError("bad value").WithPrefix("--bounds");
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(s.message(), "--bounds: bad value");
  EXPECT_TRUE(Status::Ok().WithPrefix("context").ok());
  EXPECT_EQ(Status::Ok().WithPrefix("context").message(), "");
}

TEST(StatusOr, HoldsAValue) {
  StatusOr<std::string> v(std::string("paper"));
  ASSERT_TRUE(v.ok());
  EXPECT_TRUE(v.status().ok());
  EXPECT_EQ(*v, "paper");
  EXPECT_EQ(v->size(), 5u);
  v.value() += "!";
  EXPECT_EQ(v.value(), "paper!");
}

TEST(StatusOr, HoldsAnErrorStatus) {
  const StatusOr<int> e(NotFoundError("missing"));
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.status().code(), StatusCode::kNotFound);
  EXPECT_EQ(e.status().message(), "missing");
}

TEST(StatusOr, MovesMoveOnlyValuesOut) {
  StatusOr<std::unique_ptr<int>> v(std::make_unique<int>(7));
  std::unique_ptr<int> taken = std::move(v).value();
  ASSERT_NE(taken, nullptr);
  EXPECT_EQ(*taken, 7);
}

Status FailsWhen(bool fail) { return fail ? IoError("disk") : Status::Ok(); }

Status Chain(bool fail, bool* reached_end) {
  IMUSYSID_RETURN_IF_ERROR(FailsWhen(fail));
  *reached_end = true;
  return Status::Ok();
}

TEST(StatusMacro, ReturnIfErrorReturnsEarlyOnlyOnError) {
  bool reached = false;
  EXPECT_TRUE(Chain(false, &reached).ok());
  EXPECT_TRUE(reached);
  reached = false;
  const Status s = Chain(true, &reached);
  EXPECT_EQ(s.code(), StatusCode::kIoError);
  EXPECT_FALSE(reached);
}

TEST(StatusOrDeathTest, AccessingTheValueOfAnErrorIsAProgrammerError) {
  ::testing::FLAGS_gtest_death_test_style = "threadsafe";
  const StatusOr<int> e(InvalidArgumentError("no value here"));
  EXPECT_DEATH((void)e.value(), "no value here");
}

TEST(StatusOrDeathTest, BuildingFromAnOkStatusIsAProgrammerError) {
  ::testing::FLAGS_gtest_death_test_style = "threadsafe";
  EXPECT_DEATH((void)StatusOr<int>{Status::Ok()}, "without a value");
}

}  // namespace
}  // namespace imusysid
