// Dispatcher: the per-side action table keyed by message type.
#include <catch2/catch.hpp>

#include "sample_messages.h"

using namespace pvr::proto;

TEST_CASE("Dispatcher calls the handler registered for the message type") {
  Dispatcher server;
  std::string greeted;
  std::uint32_t renderId = 0;
  server.on<Hello>([&](const Hello& hello, const FrameInfo&) { greeted = hello.software; });
  server.on<RenderRotation>([&](const RenderRotation& r, const FrameInfo& info) {
    CHECK(r.stepsPerTurn == 60);
    renderId = info.requestId;
  });

  FrameDecoder decoder;
  auto stream = encode(Hello{"pvrsh"}, 1);
  const auto render = encode(RenderRotation{{0, 1, 0}, 15, 59, 60}, 2);
  stream.insert(stream.end(), render.begin(), render.end());
  decoder.feed(stream);
  while (auto frame = decoder.pop()) CHECK(server.dispatch(*frame));
  CHECK(greeted == "pvrsh");
  CHECK(renderId == 2);
}

TEST_CASE("Dispatcher sends unhandled messages to the fallback") {
  Dispatcher client;
  client.on<ImageFrame>([](const ImageFrame&, const FrameInfo&) {});
  std::string unexpected;
  std::uint32_t unexpectedId = 0;
  client.otherwise([&](const Message& message, const FrameInfo& info) {
    unexpected = messageInfo(message).name;
    unexpectedId = info.requestId;
  });
  CHECK_FALSE(client.dispatch(Hello{"x"}, FrameInfo{8, 0}));
  CHECK(unexpected == "Hello");
  CHECK(unexpectedId == 8);
  CHECK(client.handles(ImageFrame{}));
  CHECK_FALSE(client.handles(Hello{}));

  Dispatcher bare;
  CHECK_FALSE(bare.dispatch(Ok{}, FrameInfo{}));
}

TEST_CASE("a later handler for the same type replaces the earlier one") {
  Dispatcher dispatcher;
  int calls = 0;
  dispatcher.on<Ok>([&](const Ok&, const FrameInfo&) { calls += 1; });
  dispatcher.on<Ok>([&](const Ok&, const FrameInfo&) { calls += 10; });
  dispatcher.dispatch(Ok{}, FrameInfo{});
  CHECK(calls == 10);
}

TEST_CASE("a dispatcher with a handler for every type reaches each exactly once") {
  Dispatcher all;
  std::vector<std::size_t> seen;
  // One registration per sample, via the variant: std::visit gives the type.
  for (const Message& sample : pvr::proto::testing::sampleMessages()) {
    std::visit(
        [&](const auto& typed) {
          using T = std::decay_t<decltype(typed)>;
          all.on<T>([&](const T&, const FrameInfo&) { seen.push_back(messageIndex<T>()); });
        },
        sample);
  }
  for (const Message& sample : pvr::proto::testing::sampleMessages()) CHECK(all.dispatch(sample, FrameInfo{}));
  REQUIRE(seen.size() == std::variant_size_v<Message>);
  for (std::size_t i = 0; i < seen.size(); ++i) CHECK(seen[i] == i);
}
