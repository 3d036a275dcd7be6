// Session: the record behind one `pvr_session :name` object command.
//
// A session owns one connection to pvrd, the settings made with `set`, the
// image sinks (photo, callback, files) and the render sequences in flight.
// Every reply is handled on the Tcl event loop; `open`, `wait` and the
// queries that need an answer (`list status`, `list datasets`,
// `performance`) run the event loop themselves until their answer is in.
//
// Lifetime: the object command's delete proc calls Tcl_EventuallyFree, and
// every entry from Tcl (commands, file handlers) brackets its work with
// Tcl_Preserve/Tcl_Release, so a callback may delete the session it runs in.
//
// The methods live in one file per job:
//   session.cpp           lifetime, requests out, waiting for answers
//   session_open.cpp      open: connect, Hello, token challenge, SessionOpen
//   session_arrivals.cpp  what comes back: replies, errors, Close, the end of a sequence
//   reply_book.cpp        which request a message answers, and the records kept (no Tcl)
//   frame_delivery.cpp    a frame into the photo, files and the callback
//   sequence_report.cpp   timings: progress lines, tables, Tcl dicts
//   session_status.cpp    `list status` and the server's status entries
//   session_settled.cpp   what the server accepted of `set`, and its refusals
//   session_commands.cpp  the subcommands (paper 003, Table 1)
//   session_volumes.cpp   `volume add|remove|configure|list`; the list itself in volume_list.cpp
#pragma once

#include <tcl.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "connection.h"
#include "frame_image.h"
#include "animation.h"
#include "numbered_file.h"
#include "reply_book.h"
#include "scene_options.h"
#include "tcl_util.h"

namespace pvr::tcl {

// What `open` was asked for.
struct OpenRequest {
  std::string host;
  int port = 0;
  std::uint32_t ranks = 0;  // 0: the server's default
  std::string account;      // batch-system account; empty: the site's default
  std::string tokenFile;    // empty: no token
  double timeout = 30;      // seconds for each step (at least 120 for the job to start),
                            // and for the rest of any frame once it has begun
};

class Session : public Connection::Listener {
 public:
  enum class State { kClosed, kConnecting, kOpen, kFailed };

  Session(Tcl_Interp* interp, std::string name);
  ~Session() override;

  // The object command's entry point (session_commands.cpp).
  static int objCmd(ClientData data, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]);
  static void deleteCmd(ClientData data);
  static void freeProc(char* data);

  // ---- Operations behind the subcommands; each throws TclError ----
  void open(const OpenRequest& request);
  void close(const std::string& reason);
  void applySettings(const SettingsChange& change);
  std::uint32_t render(const proto::Message& request, std::uint32_t total, const std::string& label);
  int cancel();
  std::size_t wait(double timeoutSeconds);
  // Sends `request` and runs the event loop until its FINAL answer, which
  // it returns with the answers before it. With `onProgress`, each answer
  // before the FINAL one is handed to it as it arrives and starts the
  // timeout afresh (a SessionOpen waiting in a batch queue).
  std::vector<proto::Message> query(const proto::Message& request, double timeoutSeconds,
                                    const std::function<void(const proto::Message&)>& onProgress = {});
  Tcl_Obj* statusObj();
  // Runs the event loop until the server has answered every `set` sent
  // (at most `timeoutSeconds`), so that what `set` shows is what it
  // accepted; returns at once with a sequence in flight (the master
  // answers between waves) or when the session is not open.
  void settle(double timeoutSeconds);
  // The camera in force as a dict (automatic, projection, eye, look_at, up,
  // fov_y_deg or height); errors when the server cannot say now.
  Tcl_Obj* cameraObj();
  // `:s info`: the loaded dataset's grid, type, range and histogram (session_info.cpp).
  Tcl_Obj* infoObj();
  Tcl_Obj* timingObj() const;
  // Throws {PVR STATE NOTOPEN} naming `what` unless the session is open.
  void requireOpen(const char* what) const;
  // The names in the server's status entry `key` (a Tcl list, e.g.
  // `strategies`), or nullopt when the server cannot say now: the session
  // is not open, a sequence is in flight, or the server has no such entry.
  std::optional<std::vector<std::string>> serverNames(std::string_view key);

  // ---- Connection::Listener ----
  void onMessage(const proto::Decoded& message) override;
  void onRefused(const FrameIntake::Refused& frame) override;
  void onFailure(const TclError& error) override;

  Tcl_Interp* interp_;
  Tcl_Command token_ = nullptr;
  std::string name_;
  Settings settings_;
  std::uint32_t ranksWanted_ = 0;

  // Image sinks (image window|callback|file|dir); empty: off.
  std::string photo_;
  Tcl_Obj* callback_ = nullptr;  // command prefix; frame and timing appended
  Tcl_Obj* notify_ = nullptr;    // command prefix; event and details appended
  NumberedFile files_;          // `image file`: the numbered PNGs; empty: none
  std::string animatedTarget_;  // .gif or .mp4 that ffmpeg assembles; empty: none
  int animationFps_ = kDefaultFps;  // its frames per second (`image file F -fps N`)
  std::string dir_;

 private:
  std::uint32_t send(const proto::Message& message, bool synchronous);
  // The server's status entries, or nullopt when it cannot answer at once
  // (not open, or a sequence in flight: the master answers between waves).
  std::optional<std::vector<proto::KeyValue>> serverStatus();
  // Does what one routed message asks (session_arrivals.cpp).
  void act(Arrival& arrival);
  // Delivers frame `frame` of sequence `id` to the sinks; a sink that fails
  // ends the sequence with its error (frame_delivery.cpp).
  void handleFrame(std::uint32_t id, const proto::ImageFrame& frame, bool complete);
  // Ends sequence `id` early with `error`: its later frames are dropped and
  // the server is asked to stop it (unless it had its last frame).
  void abandonSequence(std::uint32_t id, bool complete, const TclError& error);
  // abandonSequence without the report (the caller reports once for many).
  void stopSequence(std::uint32_t id, bool complete);
  // Forgets the sets and layouts in flight and the refusal (a connection
  // ended or began); what was asked stays in settings_, for the next open.
  void forgetSent();
  // Sends `change` as a SetScene and remembers it until the server answers.
  void sendScene(const SettingsChange& change);
  // The server answered request `id` (a SetScene or SetLayout pvrsh
  // remembers): accepted (no error) or refused (session_settled.cpp).
  // Returns the error to report, which for a refused SetScene says what
  // it did to the session; nullopt when `id` is not one of them.
  std::optional<TclError> settled(std::uint32_t id, const std::optional<TclError>& error);
  // Ends the session from inside an arrival: the connection closes, every
  // request fails with `error`.
  void endSession(const TclError& error);
  void runImageCallback(const FrameRecord& record);
  void finishSequence(std::uint32_t id);
  void report(const TclError& error);
  void notify(const char* event, std::vector<Tcl_Obj*> details);
  void printProgress(const Sequence& seq) const;
  void printTable(const Sequence& seq) const;
  void assembleAnimation(const Sequence& seq);
  // Runs the event loop until done() or `timeoutSeconds` pass; false on
  // timeout. Throws {PVR STATE DELETED} when the session is deleted meanwhile.
  bool runEventsUntil(const std::function<bool()>& done, double timeoutSeconds);

  State state_ = State::kClosed;
  std::unique_ptr<Connection> conn_;
  std::string peer_;
  std::string serverSoftware_;
  std::uint32_t maxRanks_ = 0;
  std::uint32_t ranks_ = 0;                       // started, as SessionReady said
  std::vector<proto::ClusterSpec> layout_;        // in force, as SessionReady said
  std::uint32_t nextId_ = 1;
  ReplyBook book_;                                // requests in flight, the latest sequence
  std::uint32_t waitedId_ = 0;                    // the last sequence whose count a wait returned
  std::uint64_t framesReceived_ = 0;              // numbers the files of `image dir|file`
  std::uint64_t firstFileNumber_ = 0;             // number of a sequence's first `image file` PNG
  int waiters_ = 0;                               // `wait` calls running
  std::optional<TclError> waitError_;             // first error while waiting
  std::optional<TclError> lastFailure_;           // why the connection ended
  std::string closeReason_;                       // the server's Close reason
  bool layoutPending_ = false;                    // a layout set since open, sent with the next render
  // What the server accepted (issue 14, point 6): `settings_` is what was
  // asked, `accepted_` what the server acknowledged; a refusal puts
  // `settings_` back to `accepted_` plus the sets still unanswered.
  Settings accepted_;
  std::map<std::uint32_t, SettingsChange> scenesSent_;                   // SetScenes unanswered, by id
  std::map<std::uint32_t, std::vector<proto::ClusterSpec>> layoutsSent_;  // SetLayouts unanswered
  // The last SetScene the server refused, until the next `set` sends one:
  // a render fails with it rather than use the settings the server kept.
  std::optional<TclError> refusal_;
  bool deleted_ = false;
};

// One frame's timing as the Tcl dict the image callback and `timing` give.
Tcl_Obj* timingDict(const FrameRecord& record);
// The phases of a timing dict in FrameTiming's order ({read prep dist rend
// comp comm send}); package pvr publishes it as ::pvr::phases.
Tcl_Obj* phaseNames();

// True when ::pvr::progress is set: sequences print progress and a timing
// table on stderr (pvrsh sets it when it runs a script).
bool progressOn(Tcl_Interp* interp);

}  // namespace pvr::tcl
