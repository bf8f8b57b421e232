// resend.pace_s, the stretch of data time between two answers to a late listener
// (common/resend.hpp), is one key with one check in every process that answers: set in a file, it
// reaches the process's config; out of range, the process's validation names it by its full path
// (the program then exits 2 naming the file too: ConfigWalk.*).
#include <gtest/gtest.h>

#include <string>

#include "annotator_node.hpp"
#include "backend_node.hpp"
#include "config.hpp"
#include "densifier.hpp"
#include "mapper.hpp"

namespace traverse {
namespace {

template <class Config>
void expect_resend_pace_key() {
  Config config;
  EXPECT_EQ(config.resend.pace_us(), 5'000'000);
  load_config_text("resend:\n  pace_s: 2.5\n", "producer.yaml", config);
  EXPECT_EQ(config.resend.pace_us(), 2'500'000);
  EXPECT_FALSE(validate(config));
  load_config_text("resend:\n  pace_s: -1\n", "producer.yaml", config);
  EXPECT_NE(validate(config).value_or("").find("'resend.pace_s'"), std::string::npos);
}

TEST(ResendPaceConfig, TheBackendReadsAndChecksIt) {
  expect_resend_pace_key<backend::BackendNodeConfig>();
}
TEST(ResendPaceConfig, TheDensifierReadsAndChecksIt) {
  expect_resend_pace_key<densifier::DensifierConfig>();
}
TEST(ResendPaceConfig, TheAnnotatorReadsAndChecksIt) {
  expect_resend_pace_key<annotator::AnnotatorNodeConfig>();
}
TEST(ResendPaceConfig, TheMapperReadsAndChecksIt) {
  expect_resend_pace_key<mapper::MapperConfig>();
}

}  // namespace
}  // namespace traverse
