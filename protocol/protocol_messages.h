// Every PVR message: one struct per type, and the Message variant that is
// the protocol's table of messages.
//
// A message struct carries
//   - kWire: its wire type number, its name and the Limits field that bounds
//     its payload;
//   - fields(self): its payload fields in wire order (field_codec.h says how
//     each field type is encoded);
//   - optionally check(limits): rules between fields that decoding enforces;
//   - optionally, when the last field is a bulk byte array (ImageFrame's
//     pixels), headFields(self) listing the fields before it and
//     checkHead(bulkBytes, limits) holding check()'s rules, so that a relay
//     checks the frame without copying the bulk (message_table.h).
// Adding a message is one struct here plus one line in `Message` below; the
// look-up table (message_table.h), the codec and the dispatcher follow.
// docs/protocol.md documents every payload byte by byte.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <variant>
#include <vector>

#include "frame_header.h"
#include "protocol_error.h"

namespace pvr::proto {

// What the message table knows of a type besides its fields.
struct WireInfo {
  std::uint8_t type;                    // header byte 5; never 0
  std::string_view name;                // "ImageFrame"
  std::uint32_t Limits::*maxPayload;    // the limit that bounds its payload
};

// ---- Enumerations carried in payloads (u8 on the wire) ----

// kCache: ranks that read time steps ahead for the render ranks (docs/runtime.md).
enum class ClusterRole : std::uint8_t { kRender = 0, kComposite = 1, kCollector = 2, kCache = 3 };
enum class PixelFormat : std::uint8_t { kRgb8 = 0, kRgba8 = 1 };
enum class Compression : std::uint8_t { kNone = 0, kRle = 1, kZlib = 2 };
enum class PerformanceQuery : std::uint8_t { kMemory = 0, kCompositing = 1, kCache = 2 };

constexpr bool isWireValue(ClusterRole v) { return v <= ClusterRole::kCache; }
constexpr bool isWireValue(PixelFormat v) { return v <= PixelFormat::kRgba8; }
constexpr bool isWireValue(Compression v) { return v <= Compression::kZlib; }
constexpr bool isWireValue(PerformanceQuery v) { return v <= PerformanceQuery::kCache; }
// Error codes pass through unchecked: a peer may know codes this build does not.
constexpr bool isWireValue(ErrorCode) { return true; }

constexpr std::uint32_t channelCount(PixelFormat format) { return format == PixelFormat::kRgba8 ? 4 : 3; }
// "none", "RLE", "zlib": for error texts.
constexpr std::string_view compressionName(Compression c) {
  return c == Compression::kNone ? "none" : c == Compression::kRle ? "RLE" : "zlib";
}

// ---- Records used inside payloads ----

// One cluster of the session layout (paper 003, Table 1: set -cluster/-group).
struct ClusterSpec {
  ClusterRole role = ClusterRole::kRender;
  std::uint32_t ranks = 0;  // 0: the master sizes the cluster
  std::uint32_t group = 0;  // clusters of one group share the scanlines of one frame
  static auto fields(auto& self) { return std::tie(self.role, self.ranks, self.group); }
  bool operator==(const ClusterSpec&) const = default;
};

// Where the time of one frame went, in seconds, as measured on the ranks
// (max over ranks per phase). The phases of a first frame add up: reading
// the bricks, preprocessing them (value range, macrocell bounds, distance
// field, classification), distributing (decomposition, scatter, view),
// rendering, compositing, waiting, and the collector's send.
struct FrameTiming {
  double read = 0;         // reading brick voxels from the files
  double preprocess = 0;   // value range, macrocells, distance field, classification
  double distribute = 0;   // sending view and bricks to the rendering clusters
  double render = 0;       // ray casting
  double composite = 0;    // compositing
  double communicate = 0;  // waiting on other ranks
  double send = 0;         // collector: conversion, compression and send
  static auto fields(auto& self) {
    return std::tie(self.read, self.preprocess, self.distribute, self.render, self.composite, self.communicate,
                    self.send);
  }
  bool operator==(const FrameTiming&) const = default;
};
static_assert(sizeof(FrameTiming) == kFrameTimingBytes, "FrameTiming's wire size is kFrameTimingBytes");

// One dataset of the catalog, listed once under its stem ("head" for
// head.json and head.nhdr): its name relative to the data directory, its
// number of time steps (1 for a single volume), the file it opens from,
// the format's name, its dims and scalar type, and why it cannot be loaded
// (empty when it can; dims 0 0 0 and dtype empty then).
struct CatalogEntry {
  std::string name;
  std::uint32_t steps = 1;
  std::string file;
  std::string format;
  std::array<std::uint32_t, 3> dims{0, 0, 0};
  std::string dtype;
  std::string note;
  static auto fields(auto& self) {
    return std::tie(self.name, self.steps, self.file, self.format, self.dims, self.dtype, self.note);
  }
  bool operator==(const CatalogEntry&) const = default;
};

struct KeyValue {
  std::string key;
  std::string value;
  static auto fields(auto& self) { return std::tie(self.key, self.value); }
  bool operator==(const KeyValue&) const = default;
};

inline constexpr std::size_t kNonceBytes = 32;  // AuthChallenge nonce
inline constexpr std::size_t kMacBytes = 32;    // HMAC-SHA256 output

// ---- Connection: hello, authentication, acknowledgement, error, close ----

// Client -> server, first message of a connection.
struct Hello {
  static constexpr WireInfo kWire{0x01, "Hello", &Limits::maxControlPayload};
  std::string software;  // "pvrsh 0.1"
  static auto fields(auto& self) { return std::tie(self.software); }
  bool operator==(const Hello&) const = default;
};

// Server -> client, answers Hello.
struct Welcome {
  static constexpr WireInfo kWire{0x02, "Welcome", &Limits::maxControlPayload};
  std::string software;       // "pvrd 0.1"
  std::uint32_t maxRanks = 0; // the most ranks a session may ask for
  bool authRequired = false;  // the secure channel keyed by the token follows
  static auto fields(auto& self) { return std::tie(self.software, self.maxRanks, self.authRequired); }
  bool operator==(const Welcome&) const = default;
};

// Server -> client: prove knowledge of the shared token.
struct AuthChallenge {
  static constexpr WireInfo kWire{0x03, "AuthChallenge", &Limits::maxControlPayload};
  std::array<std::uint8_t, kNonceBytes> nonce{};  // fresh random bytes
  static auto fields(auto& self) { return std::tie(self.nonce); }
  bool operator==(const AuthChallenge&) const = default;
};

// Client -> server: HMAC-SHA256(token, nonce). The protocol carries bytes only.
struct AuthResponse {
  static constexpr WireInfo kWire{0x04, "AuthResponse", &Limits::maxControlPayload};
  std::array<std::uint8_t, kMacBytes> mac{};
  static auto fields(auto& self) { return std::tie(self.mac); }
  bool operator==(const AuthResponse&) const = default;
};

// Either direction: the request with this id succeeded.
struct Ok {
  static constexpr WireInfo kWire{0x05, "Ok", &Limits::maxControlPayload};
  static auto fields(auto&) { return std::tie(); }
  bool operator==(const Ok&) const = default;
};

// Either direction: the request with this id failed (id 0: the connection did).
struct ErrorMessage {
  static constexpr WireInfo kWire{0x06, "Error", &Limits::maxControlPayload};
  ErrorCode code = ErrorCode::kInternal;
  std::string text;
  static auto fields(auto& self) { return std::tie(self.code, self.text); }
  bool operator==(const ErrorMessage&) const = default;
};

// Either direction: the sender closes the connection after this frame.
struct Close {
  static constexpr WireInfo kWire{0x07, "Close", &Limits::maxControlPayload};
  std::string reason;
  static auto fields(auto& self) { return std::tie(self.reason); }
  bool operator==(const Close&) const = default;
};

// Master rank -> session handler, the first frame on the connect-back: the
// one-time secret pvrd handed to the job in its environment, so that the
// handler relays nothing for a connection that is not the job it launched.
// The environment variable that carries the secret to the job: pvrd sets
// it (and exports it to every rank with mpirun -x), the master reads it.
inline constexpr const char* kJobSecretVariable = "PVR_JOB_SECRET";

struct JobHello {
  static constexpr WireInfo kWire{0x08, "JobHello", &Limits::maxControlPayload};
  std::string secret;  // PVR_JOB_SECRET as the job received it
  static auto fields(auto& self) { return std::tie(self.secret); }
  bool operator==(const JobHello&) const = default;
};

// Master rank -> session handler, every kHeartbeatSeconds for the whole
// session, request id 0: the master process runs. The master's own
// watchdog sees its ranks stop (node/rank_watch.h), but nothing inside the
// job sees rank 0 itself stopped; the handler does, by these frames
// ceasing. Never relayed to a client.
inline constexpr int kHeartbeatSeconds = 2;

struct Heartbeat {
  static constexpr WireInfo kWire{0x09, "Heartbeat", &Limits::maxControlPayload};
  static auto fields(auto&) { return std::tie(); }
  bool operator==(const Heartbeat&) const = default;
};

// ---- Session and scene ----

// Client -> server: start the MPI job.
struct SessionOpen {
  static constexpr WireInfo kWire{0x10, "SessionOpen", &Limits::maxControlPayload};
  std::uint32_t rankCount = 0;        // 0: the daemon's default
  std::vector<ClusterSpec> clusters;  // empty: the master's default layout
  std::string account;                // batch-system account to charge ("": the site's default)
  static auto fields(auto& self) { return std::tie(self.rankCount, self.clusters, self.account); }
  bool operator==(const SessionOpen&) const = default;
};

// Server -> client, answers SessionOpen and SetLayout: the layout in force.
struct SessionReady {
  static constexpr WireInfo kWire{0x11, "SessionReady", &Limits::maxControlPayload};
  std::uint32_t rankCount = 0;
  std::vector<ClusterSpec> clusters;
  static auto fields(auto& self) { return std::tie(self.rankCount, self.clusters); }
  bool operator==(const SessionReady&) const = default;
};

// Client -> server: change the dataset and/or any scene parameter.
struct SetScene {
  static constexpr WireInfo kWire{0x12, "SetScene", &Limits::maxTextPayload};
  std::string dataset;    // a catalog name; empty: unchanged
  std::string sceneJson;  // a partial scene document merged into the scene; empty: unchanged
  static auto fields(auto& self) { return std::tie(self.dataset, self.sceneJson); }
  bool operator==(const SetScene&) const = default;
};

// Client -> server: re-arrange the clusters of an open session.
struct SetLayout {
  static constexpr WireInfo kWire{0x13, "SetLayout", &Limits::maxControlPayload};
  std::vector<ClusterSpec> clusters;
  static auto fields(auto& self) { return std::tie(self.clusters); }
  bool operator==(const SetLayout&) const = default;
};

// ---- Rendering ----

// Client -> server: one frame of the current scene (frame number 0).
struct RenderFrame {
  static constexpr WireInfo kWire{0x20, "RenderFrame", &Limits::maxControlPayload};
  static auto fields(auto&) { return std::tie(); }
  bool operator==(const RenderFrame&) const = default;
};

// Client -> server: frames k = start..end of a rotation of the camera about
// `axis` through its look-at point (for the automatic camera, the volume
// centre): frame k turns the eye and up vectors by 360 degrees * k /
// stepsPerTurn ("render rotate 0,1,0 15,59:60" of paper 003 is 45 frames).
struct RenderRotation {
  static constexpr WireInfo kWire{0x21, "RenderRotation", &Limits::maxControlPayload};
  std::array<double, 3> axis{0, 1, 0};
  std::int32_t start = 0;
  std::int32_t end = 0;
  std::uint32_t stepsPerTurn = 1;
  static auto fields(auto& self) { return std::tie(self.axis, self.start, self.end, self.stepsPerTurn); }
  // stepsPerTurn >= 1, start <= end, at most limits.maxRotationFrames frames
  // (kLimitExceeded), a finite nonzero axis; the others are kBadArgument.
  // Decoding enforces it; a client may call it before sending.
  std::optional<ProtocolError> check(const Limits& limits) const;
  // end - start + 1; meaningful once check() passed.
  std::uint32_t frameCount() const { return static_cast<std::uint32_t>(std::int64_t{end} - start + 1); }
  bool operator==(const RenderRotation&) const = default;
};

// Client -> server: one frame per time step first, first + stride, ...
// up to last (inclusive) of a time-series dataset, at the current view, in
// order: frame k shows step first + k * stride. Steps are 0-based.
struct RenderTimeSteps {
  static constexpr WireInfo kWire{0x24, "RenderTimeSteps", &Limits::maxControlPayload};
  std::uint32_t first = 0;
  std::uint32_t last = 0;
  std::uint32_t stride = 1;
  static auto fields(auto& self) { return std::tie(self.first, self.last, self.stride); }
  // stride >= 1 and first <= last (kBadArgument), at most
  // limits.maxRotationFrames frames (kLimitExceeded). Whether the steps
  // exist is the server's to check against the dataset.
  std::optional<ProtocolError> check(const Limits& limits) const;
  // (last - first) / stride + 1; meaningful once check() passed.
  std::uint32_t frameCount() const { return (last - first) / stride + 1; }
  bool operator==(const RenderTimeSteps&) const = default;
};

// Client -> server: advances the session's computation volume (docs/steering.md)
// `steps` steps and renders one frame every `every` steps and one of the
// last: frame k shows step s0 + min((k + 1) * every, steps), s0 being the
// step shown before. The simulation runs on the ranks; nothing touches disk.
struct RenderSteps {
  static constexpr WireInfo kWire{0x25, "RenderSteps", &Limits::maxControlPayload};
  std::uint32_t steps = 1;
  std::uint32_t every = 1;
  static auto fields(auto& self) { return std::tie(self.steps, self.every); }
  // steps >= 1 and every >= 1 (kBadArgument), at most
  // limits.maxRotationFrames frames (kLimitExceeded). Whether the volume is
  // a computation is the server's to check.
  std::optional<ProtocolError> check(const Limits& limits) const;
  // ceil(steps / every); meaningful once check() passed.
  std::uint32_t frameCount() const { return steps / every + (steps % every != 0 ? 1 : 0); }
  bool operator==(const RenderSteps&) const = default;
};

// Client -> server: one frame of the current view, progressively (a view
// that is being dragged): first a coarse frame, 1/reduction of the pixels
// per axis and sent at that size, for the client to zoom to the image size
// (ImageFrame 0, not FINAL; docs/protocol.md), then the
// full-quality frame (ImageFrame 1, FINAL) unless a newer request arrived
// meanwhile, which ends this one with Error CANCELLED. The view is the
// session's camera turned by 360 degrees * turn / stepsPerTurn about `axis`
// through its look-at point, as frame `turn` of a RenderRotation (turn 0:
// the camera as it is). Older servers do not know the type: a client falls
// back to RenderFrame or RenderRotation.
inline constexpr std::uint32_t kMaxInteractiveReduction = 16;

struct RenderInteractive {
  static constexpr WireInfo kWire{0x26, "RenderInteractive", &Limits::maxControlPayload};
  std::uint32_t reduction = 4;  // 2 .. kMaxInteractiveReduction
  std::array<double, 3> axis{0, 0, 1};
  std::int32_t turn = 0;
  std::uint32_t stepsPerTurn = 1;
  static auto fields(auto& self) { return std::tie(self.reduction, self.axis, self.turn, self.stepsPerTurn); }
  // reduction in 2 .. kMaxInteractiveReduction, and the view's turn passes
  // RenderRotation::check as a one-frame rotation; kBadArgument otherwise.
  std::optional<ProtocolError> check(const Limits& limits) const;
  // The view as the one-frame rotation it is.
  RenderRotation rotation() const { return RenderRotation{axis, turn, turn, stepsPerTurn}; }
  bool operator==(const RenderInteractive&) const = default;
};

// Server -> client: one rendered frame.
struct ImageFrame {
  static constexpr WireInfo kWire{0x22, "ImageFrame", &Limits::maxFrameBytes};
  std::uint32_t frameNumber = 0;  // position in its request: 0, 1, 2, ...
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  PixelFormat format = PixelFormat::kRgb8;
  Compression compression = Compression::kNone;
  FrameTiming timing;
  std::vector<std::uint8_t> pixels;  // rows top to bottom, 8-bit sRGB, as compressed (pixel_codec.h)
  // The fields before the pixels. A relay reads only these and the pixel
  // byte count, and checks them with checkHead, without copying the pixels.
  static auto headFields(auto& self) {
    return std::tie(self.frameNumber, self.width, self.height, self.format, self.compression, self.timing);
  }
  static auto fields(auto& self) { return std::tuple_cat(headFields(self), std::tie(self.pixels)); }
  // The rules between the head fields and a pixel byte count: width, height
  // >= 1 and the size passes checkImageSize (image_limits.h); uncompressed
  // pixels are exactly width * height * channels bytes, compressed ones
  // fewer (a sender falls back to kNone when compressing does not pay).
  std::optional<ProtocolError> checkHead(std::uint64_t pixelBytes, const Limits& limits) const;
  std::optional<ProtocolError> check(const Limits& limits) const { return checkHead(pixels.size(), limits); }
  bool operator==(const ImageFrame&) const = default;
};

// Client -> server: stop the request `target`; it ends with Error kCancelled.
struct Cancel {
  static constexpr WireInfo kWire{0x23, "Cancel", &Limits::maxControlPayload};
  std::uint32_t target = 0;
  static auto fields(auto& self) { return std::tie(self.target); }
  bool operator==(const Cancel&) const = default;
};

// ---- Queries ----

struct StatusRequest {
  static constexpr WireInfo kWire{0x30, "StatusRequest", &Limits::maxControlPayload};
  static auto fields(auto&) { return std::tie(); }
  bool operator==(const StatusRequest&) const = default;
};

// Connection state and internal variables ("list status"), in order.
struct StatusReply {
  static constexpr WireInfo kWire{0x31, "StatusReply", &Limits::maxTextPayload};
  std::vector<KeyValue> entries;
  static auto fields(auto& self) { return std::tie(self.entries); }
  bool operator==(const StatusReply&) const = default;
};

inline constexpr std::uint32_t kAllClusters = 0xFFFFFFFFu;

// "performance memory cluster" / "performance comp cluster latency".
struct PerformanceRequest {
  static constexpr WireInfo kWire{0x32, "PerformanceRequest", &Limits::maxControlPayload};
  PerformanceQuery query = PerformanceQuery::kMemory;
  std::uint32_t cluster = kAllClusters;  // cluster index, or kAllClusters
  static auto fields(auto& self) { return std::tie(self.query, self.cluster); }
  bool operator==(const PerformanceRequest&) const = default;
};

// A JSON document whose keys docs/protocol.md lists per query.
struct PerformanceReply {
  static constexpr WireInfo kWire{0x33, "PerformanceReply", &Limits::maxTextPayload};
  PerformanceQuery query = PerformanceQuery::kMemory;
  std::string json;
  static auto fields(auto& self) { return std::tie(self.query, self.json); }
  bool operator==(const PerformanceReply&) const = default;
};

struct CatalogRequest {
  static constexpr WireInfo kWire{0x34, "CatalogRequest", &Limits::maxControlPayload};
  static auto fields(auto&) { return std::tie(); }
  bool operator==(const CatalogRequest&) const = default;
};

// The datasets the server can open, sorted by name; a time series once.
struct CatalogReply {
  static constexpr WireInfo kWire{0x35, "CatalogReply", &Limits::maxTextPayload};
  std::vector<CatalogEntry> datasets;
  static auto fields(auto& self) { return std::tie(self.datasets); }
  bool operator==(const CatalogReply&) const = default;
};

// The message table: one line per message type. Order is free (wire type
// numbers live in kWire); message_table.cpp checks they are unique.
using Message = std::variant<
    Hello, Welcome, AuthChallenge, AuthResponse, Ok, ErrorMessage, Close, JobHello,
    SessionOpen, SessionReady, SetScene, SetLayout,
    RenderFrame, RenderRotation, RenderTimeSteps, RenderSteps, RenderInteractive, ImageFrame, Cancel,
    StatusRequest, StatusReply, PerformanceRequest, PerformanceReply, CatalogRequest, CatalogReply, Heartbeat>;

// Whether `m` asks for frames (RenderFrame, RenderRotation, RenderTimeSteps,
// RenderSteps, RenderInteractive): a sequence whose answers are frames, the
// last FINAL, which may stream for a long time.
bool isRenderRequest(const Message& m);

// Whether `m` only asks about the session (StatusRequest,
// PerformanceRequest, CatalogRequest): it changes nothing and asks for no
// frames, so it may be answered between or during another request's work.
bool isQuery(const Message& m);

}  // namespace pvr::proto
