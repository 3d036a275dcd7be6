// The fake MPI job of fake_master.h. pvrd calls it as
//   fake_master --oversubscribe ... -np N -x PVR_JOB_SECRET NODE --server --connect HOST:PORT --data-dir DIR
// It makes the connect-back trials it is asked for, then serves one
// connection and exits when it closes.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <thread>

#include <memory>

#include "fake_master.h"
#include "secure_channel.h"

namespace proto = pvr::proto;
using namespace pvr::daemon::testing;

namespace {

int gSocket = -1;
std::unique_ptr<proto::SecureChannel> gChannel;  // null: plain bytes (the "none" trial)

void writeRaw(std::span<const std::uint8_t> bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::send(gSocket, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n <= 0) std::exit(0);  // pvrd went away
    done += std::size_t(n);
  }
}

// Plaintext for pvrd, through the channel when there is one.
void sendBytes(std::span<const std::uint8_t> bytes) {
  if (!gChannel) return writeRaw(bytes);
  if (gChannel->send(bytes)) std::exit(0);
  writeRaw(gChannel->takeOutgoing());
}

// The channel's handshake keyed by `secret`; false when pvrd refuses it.
bool handshake(const std::string& secret) {
  gChannel = std::make_unique<proto::SecureChannel>(proto::SecureChannel::Role::kClient, secret,
                                                    proto::kConnectBackPurpose);
  writeRaw(gChannel->takeOutgoing());
  std::uint8_t buf[4096];
  while (!gChannel->established()) {
    const ssize_t n = ::read(gSocket, buf, sizeof buf);
    if (n <= 0) return false;
    const auto failure = gChannel->receive(std::span(buf, std::size_t(n)));
    writeRaw(gChannel->takeOutgoing());
    if (failure) return false;
  }
  return true;
}

void send(const proto::Message& m, std::uint32_t id, bool final = true) {
  sendBytes(proto::encode(m, id, final ? proto::kFlagFinal : 0));
}

void render(const std::string& script, std::uint32_t id) {
  if (script == kScriptOversize) {
    const std::uint32_t over = proto::kMaxFrameBytes - proto::kHeaderBytes + 1;
    std::vector<std::uint8_t> header(proto::kHeaderBytes);
    proto::writeHeader({proto::kProtocolVersion, proto::ImageFrame::kWire.type, 0, id, over},
                       std::span(header).first<proto::kHeaderBytes>());
    sendBytes(header);
    const std::vector<std::uint8_t> chunk(1 << 20, 0x5A);
    for (std::uint32_t left = over; left > 0;) {
      const std::uint32_t n = std::min<std::uint32_t>(left, std::uint32_t(chunk.size()));
      sendBytes(std::span(chunk).first(n));
      left -= n;
    }
    send(fakeGoodFrame(), id);
  } else if (script == kScriptInconsistent) {
    proto::ImageFrame frame{0, 2, 2, proto::PixelFormat::kRgb8, proto::Compression::kNone, {},
                            std::vector<std::uint8_t>(11, 1)};
    send(frame, id);
  } else if (script == kScriptGarbage) {
    const std::string text = "GARBAGE, NOT A FRAME";
    sendBytes(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  } else {
    send(fakeGoodFrame(), id);
  }
}

int connectTo(const std::string& host, int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(std::uint16_t(port));
  ::inet_pton(AF_INET, host.c_str(), &a.sin_addr);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    std::perror("fake_master: connect");
    std::exit(1);
  }
  return fd;
}

// Waits until the handler closes `fd`; exits with status 3 if it does not.
void expectClosed(int fd, const std::string& trial) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  std::uint8_t buf[256];
  while (std::chrono::steady_clock::now() < until) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) {
      ::close(fd);
      return;
    }
  }
  std::fprintf(stderr, "fake_master: pvrd kept the '%s' connect-back open\n", trial.c_str());
  std::exit(3);
}

// The connect-backs pvrd must refuse, as kTrialsVariable lists them.
void tryRefusedConnectBacks(const std::string& host, int port) {
  const char* list = std::getenv(kTrialsVariable);
  std::istringstream trials(list ? list : "");
  for (std::string trial; std::getline(trials, trial, ',');) {
    // A silent connection is never closed here: it stays open while the
    // master connects.
    gSocket = connectTo(host, port);
    gChannel.reset();
    if (trial == kTrialSilent) continue;
    const char* secret = std::getenv("PVR_JOB_SECRET");
    if (trial == kTrialWrongSecret) {
      handshake(std::string(kWrongSecret));
    } else if (trial == kTrialNoSecret) {
      send(proto::JobHello{""}, 0);
    } else if (handshake(secret ? secret : "")) {
      if (trial == kTrialWrongJobHello) send(proto::JobHello{std::string(kWrongSecret)}, 0);
      else send(proto::SessionReady{2, {}}, 0);
    }
    expectClosed(gSocket, trial);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string connect;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--connect") connect = argv[i + 1];
  const auto colon = connect.rfind(':');
  if (colon == std::string::npos) {
    std::fprintf(stderr, "fake_master: no --connect HOST:PORT\n");
    return 2;
  }
  const std::string host = connect.substr(0, colon);
  const int port = std::atoi(connect.c_str() + colon + 1);
  tryRefusedConnectBacks(host, port);
  gSocket = connectTo(host, port);
  const char* secret = std::getenv("PVR_JOB_SECRET");
  if (!handshake(secret ? secret : "")) return 1;
  send(proto::JobHello{secret ? secret : ""}, 0);
  proto::FrameDecoder decoder;
  std::string script(kScriptGood);
  std::vector<std::uint8_t> buf(65536);
  for (;;) {
    const ssize_t n = ::read(gSocket, buf.data(), buf.size());
    if (n <= 0) return 0;
    if (gChannel->receive(std::span(buf.data(), std::size_t(n)))) return 1;
    decoder.feed(gChannel->takeIncoming());
    while (auto d = decoder.pop()) {
      const std::uint32_t id = d->info.requestId;
      if (const auto* open = std::get_if<proto::SessionOpen>(&d->message)) {
        send(proto::SessionReady{open->rankCount, {}}, id);
      } else if (const auto* scene = std::get_if<proto::SetScene>(&d->message)) {
        script = scene->sceneJson;
        send(proto::Ok{}, id);
      } else if (std::holds_alternative<proto::RenderFrame>(d->message)) {
        render(script, id);
      } else if (std::holds_alternative<proto::Close>(d->message)) {
        return 0;
      } else {
        send(proto::ErrorMessage{proto::ErrorCode::kUnsupported, "the fake master does not serve this"}, id);
      }
    }
    if (decoder.error()) return 1;
  }
}
