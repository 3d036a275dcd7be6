// The look-up table generated from the Message variant: one entry per type,
// unique type numbers, per-type limits.
#include <catch2/catch.hpp>

#include <set>

#include "sample_messages.h"

using namespace pvr::proto;

TEST_CASE("the table has one entry per message type, found by its wire number") {
  const auto table = messageTable();
  REQUIRE(table.size() == std::variant_size_v<Message>);
  std::set<std::uint8_t> types;
  std::set<std::string_view> names;
  for (std::size_t i = 0; i < table.size(); ++i) {
    const MessageInfo& info = table[i];
    CHECK(info.index == i);
    CHECK(info.type != 0);
    types.insert(info.type);
    names.insert(info.name);
    REQUIRE(findMessage(info.type) == &info);
  }
  CHECK(types.size() == table.size());
  CHECK(names.size() == table.size());
  CHECK(findMessage(0) == nullptr);
  CHECK(findMessage(0xFF) == nullptr);
}

TEST_CASE("the samples cover every message type in variant order") {
  const auto samples = pvr::proto::testing::sampleMessages();
  REQUIRE(samples.size() == std::variant_size_v<Message>);
  for (std::size_t i = 0; i < samples.size(); ++i) CHECK(samples[i].index() == i);
}

TEST_CASE("messageIndex and messageInfo agree with the variant") {
  CHECK(messageIndex<Hello>() == 0);
  CHECK(messageInfo(Message{ImageFrame{}}).name == "ImageFrame");
  CHECK(messageInfo(Message{ImageFrame{}}).index == messageIndex<ImageFrame>());
  CHECK(messageInfo(Message{ErrorMessage{}}).name == "Error");
}

TEST_CASE("payload limits: control messages small, image frames up to the frame limit") {
  const Limits limits;
  const auto limitOf = [&](const Message& m) { return payloadLimit(messageInfo(m), limits); };
  CHECK(limitOf(Hello{}) == limits.maxControlPayload);
  CHECK(limitOf(SetScene{}) == limits.maxTextPayload);
  CHECK(limitOf(CatalogReply{}) == limits.maxTextPayload);
  CHECK(limitOf(ImageFrame{}) == kMaxFrameBytes - kHeaderBytes);

  // Every limit is capped so that header + payload fit maxFrameBytes.
  Limits tight;
  tight.maxFrameBytes = 1000;
  CHECK(payloadLimit(messageInfo(SetScene{}), tight) == 1000 - kHeaderBytes);
  tight.maxFrameBytes = 3;
  CHECK(payloadLimit(messageInfo(Hello{}), tight) == 0);
}
