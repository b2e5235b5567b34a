// The progress line: the ETA from the recent rate, each phase named, and
// the line ended when an interrupt comes while it is shown. The lines are
// drawn into a pipe here instead of a terminal.
#include "app/render/progress.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <string>

namespace {

// Rings4 at 512x512: 300 k pixels/s for 0.3 s, then 62 k/s. At 2.4 s the
// ETA is what is left at 62 k/s, not at the 92 k/s average since the start.
TEST(RecentRate, TheEtaFollowsTheRecentRate) {
  app::RecentRate rate;
  std::uint64_t done = 0;
  for (double t = 0; t < 0.3 - 1e-9; t += 0.05) rate.add(t, done), done += 15000;
  for (double t = 0.3; t < 2.4 + 1e-9; t += 0.05) rate.add(t, done), done += 3100;
  const std::uint64_t total = 512 * 512;
  ASSERT_LT(done, total);
  EXPECT_NEAR(rate.per_second(), 62000, 100);
  const auto eta = app::eta_seconds(rate, done, total);
  ASSERT_TRUE(eta.has_value());
  EXPECT_NEAR(*eta, double(total - done) / 62000, 0.01);
}

TEST(RecentRate, NoEtaBeforeARate) {
  app::RecentRate rate;
  EXPECT_FALSE(app::eta_seconds(rate, 0, 10).has_value());
  rate.add(0, 0);
  EXPECT_FALSE(app::eta_seconds(rate, 0, 10).has_value());
  rate.add(1, 5);
  EXPECT_EQ(app::eta_seconds(rate, 5, 10), 1.0);
}

class ProgressLine : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(::pipe(fds_), 0);
    ASSERT_EQ(::fcntl(fds_[0], F_SETFL, O_NONBLOCK), 0);
  }
  void TearDown() override {
    ::close(fds_[0]);
    ::close(fds_[1]);
  }
  std::string drawn() {
    std::string text;
    char buffer[4096];
    for (ssize_t n; (n = ::read(fds_[0], buffer, sizeof buffer)) > 0;) text.append(buffer, static_cast<std::size_t>(n));
    return text;
  }
  int fds_[2] = {-1, -1};
};

// Each phase is named on the line while it runs, and the line is cleared
// as it ends.
TEST_F(ProgressLine, EachPhaseIsNamedThenCleared) {
  {
    const app::PhaseNote note("reading teapot.nff", true, fds_[1]);
    EXPECT_EQ(drawn(), "\rreading teapot.nff...\033[K");
  }
  EXPECT_EQ(drawn(), "\r\033[K");
  app::ProgressBar bar(100, "pixels", true, "render", fds_[1]);
  EXPECT_EQ(drawn().rfind("\rrender [", 0), 0u) << "drawn at once, before any work is done";
  bar.update(100);
  EXPECT_NE(drawn().find("100/100 pixels"), std::string::npos);
  bar.finish();
  EXPECT_EQ(drawn(), "\r\033[K");
}

// A bar with a setup says so until the work reports, and only then draws
// the bar, with a clock that starts there.
TEST_F(ProgressLine, ASetupIsNamedUntilTheWorkBegins) {
  app::ProgressBar bar(100, "pixels", true, "render", fds_[1], "starting the machine");
  EXPECT_EQ(drawn(), "\rstarting the machine...\033[K");
  bar.update(0);
  const std::string first = drawn();
  EXPECT_EQ(first.rfind("\rrender [", 0), 0u) << first;
  EXPECT_NE(first.find("0/100 pixels"), std::string::npos) << first;
  EXPECT_NE(first.find("ETA --"), std::string::npos) << "no rate yet: " << first;
  bar.update(100);
  EXPECT_NE(drawn().find("100/100 pixels"), std::string::npos);
  bar.finish();
  EXPECT_EQ(drawn(), "\r\033[K");
}

// An interrupt while the bar is shown clears the line first, then goes on
// to the handler there was before (here the test's; by default, the end of
// the process).
TEST_F(ProgressLine, AnInterruptEndsTheLineThenTakesItsCourse) {
  static volatile std::sig_atomic_t delivered = 0;
  const auto before = std::signal(SIGINT, [](int) { delivered = 1; });
  {
    app::ProgressBar bar(100, "pixels", true, "render", fds_[1]);
    bar.update(40);
    drawn();
    std::raise(SIGINT);
    EXPECT_EQ(delivered, 1);
    EXPECT_EQ(drawn(), "\r\033[K");
  }
  EXPECT_EQ(drawn(), "") << "nothing more once the line is ended";
  delivered = 0;
  std::raise(SIGINT);
  EXPECT_EQ(delivered, 1) << "the handler of before is back";
  std::signal(SIGINT, before);
}

}  // namespace
