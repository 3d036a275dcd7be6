// The one-time job secret and the JobHello check on a connect-back.
#include <catch2/catch.hpp>

#include <regex>

#include "auth.h"
#include "job_hello_check.h"
#include "pvr_protocol.h"

using namespace pvr::daemon;
namespace proto = pvr::proto;

namespace {

std::vector<std::uint8_t> operator+(std::vector<std::uint8_t> a, const std::vector<std::uint8_t>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

std::string refusal(const JobHelloCheck::Result& r) {
  REQUIRE(std::holds_alternative<JobHelloCheck::Refused>(r));
  return std::get<JobHelloCheck::Refused>(r).reason;
}

}  // namespace

TEST_CASE("job secrets are 64 lowercase hex digits, fresh each time, compared exactly") {
  const auto a = makeJobSecret(), b = makeJobSecret();
  REQUIRE(a);
  REQUIRE(b);
  CHECK(std::regex_match(*a, std::regex("[0-9a-f]{64}")));
  CHECK(*a != *b);
  CHECK(sameSecret(*a, *a));
  CHECK_FALSE(sameSecret(*a, *b));
  CHECK_FALSE(sameSecret(*a, a->substr(0, 63)));
  CHECK_FALSE(sameSecret(*a, *a + "0"));
  CHECK_FALSE(sameSecret("", ""));
}

TEST_CASE("JobHello check: the right secret is accepted, byte by byte too, and what follows is the master's") {
  const std::string secret(64, 'c');
  const auto ready = proto::encode(proto::SessionReady{2, {}}, 1, proto::kFlagFinal);
  const auto bytes = proto::encode(proto::JobHello{secret}, 0, proto::kFlagFinal) + ready;
  JobHelloCheck whole(secret);
  const auto r = whole.feed(bytes);
  REQUIRE(std::holds_alternative<JobHelloCheck::Accepted>(r));
  CHECK(std::get<JobHelloCheck::Accepted>(r).rest == ready);

  JobHelloCheck bytewise(secret);
  const auto hello = proto::encode(proto::JobHello{secret}, 0, proto::kFlagFinal);
  for (std::size_t i = 0; i + 1 < hello.size(); ++i)
    REQUIRE(std::holds_alternative<JobHelloCheck::Waiting>(bytewise.feed(std::span(&hello[i], 1))));
  const auto last = bytewise.feed(std::span(&hello.back(), 1));
  REQUIRE(std::holds_alternative<JobHelloCheck::Accepted>(last));
  CHECK(std::get<JobHelloCheck::Accepted>(last).rest.empty());
}

TEST_CASE("JobHello check: a wrong or missing secret, another first frame, or no frame is refused") {
  const std::string secret(64, 'c');
  CHECK(refusal(JobHelloCheck(secret).feed(proto::encode(proto::JobHello{std::string(64, 'd')}, 0))) ==
        "JobHello with a wrong secret");
  CHECK(refusal(JobHelloCheck(secret).feed(proto::encode(proto::JobHello{""}, 0))) == "JobHello without a secret");
  // Refused from the header alone: the 48 MiB payload it announces is never awaited.
  auto image = proto::encode(proto::ImageFrame{}, 0);
  image.resize(proto::kHeaderBytes);
  image[12] = image[13] = image[14] = 0;
  image[15] = 0x03;
  CHECK(refusal(JobHelloCheck(secret).feed(image)) == "its first frame is ImageFrame, not JobHello");
  const std::string http = "GET / HTTP/1.0\r\n";
  JobHelloCheck text(secret);
  CHECK_THAT(refusal(text.feed(std::span(reinterpret_cast<const std::uint8_t*>(http.data()), http.size()))),
             Catch::StartsWith("not a frame: "));
  CHECK(text.firstBytes() == "GET / HTTP/1.0\\x0d\\x0a");
}
