// Session: what the server accepted of `set` (issue 14, point 6).
//
// A `set` on an open session goes out as a SetScene whose answer comes
// later. Until it comes, `set` shows the value asked; when the server
// refuses it, the session forgets the value (`set OPTION`, `list status`
// show what the server holds), the refusal is reported at once, a render
// sent after the refused set is stopped, and every later render fails with
// the refusal until the next `set` is sent (docs/pvrsh.md, "Refused
// settings"). A SetLayout the server accepts becomes the layout in force.
#include "session.h"

namespace pvr::tcl {

void Session::sendScene(const SettingsChange& change) {
  const std::uint32_t id =
      send(proto::SetScene{change.dataset ? change.datasetName : std::string(),
                           change.patch.empty() ? std::string() : change.patch.dump()},
           false);
  scenesSent_[id] = change;
  // A new setting: the user acted on the refusal (its own answer may bring another).
  refusal_.reset();
}

void Session::forgetSent() {
  scenesSent_.clear();
  layoutsSent_.clear();
  refusal_.reset();
}

void Session::settle(double timeoutSeconds) {
  if (state_ != State::kOpen || !book_.sequences.empty() || scenesSent_.empty()) return;
  runEventsUntil([&] { return scenesSent_.empty() || state_ != State::kOpen || !book_.sequences.empty(); },
                 timeoutSeconds);
}

std::optional<TclError> Session::settled(std::uint32_t id, const std::optional<TclError>& error) {
  if (const auto layout = layoutsSent_.find(id); layout != layoutsSent_.end()) {
    if (!error) layout_ = layout->second;  // the layout in force from now on
    layoutsSent_.erase(layout);
    return error;
  }
  const auto scene = scenesSent_.find(id);
  if (scene == scenesSent_.end()) return error;
  if (!error) {
    applyChange(accepted_, scene->second);
    scenesSent_.erase(scene);
    return std::nullopt;
  }
  // Refused: the settings become what the server holds, with the sets sent
  // after this one (the server applies them to its own state) on top.
  std::string given = scene->second.command.empty() ? "set" : scene->second.command;
  if (scene->second.command.empty())
    for (const auto& [option, value] : scene->second.shown) given += " " + option + " " + value;
  scenesSent_.erase(scene);
  Settings kept = accepted_;
  kept.clusters = settings_.clusters;
  kept.cameraMoves = settings_.cameraMoves;
  for (const auto& [later, change] : scenesSent_) applyChange(kept, change);
  settings_ = std::move(kept);
  // Until another set goes out (one sent already clears nothing: it was
  // sent before the refusal was known, and the server applied it). Set
  // before the renders stop: their `cancelled` event may ask for another.
  refusal_ = TclError(error->code(), given + " was refused: " + error->what());
  // Renders sent after the refused set would show the old settings: stopped.
  std::vector<std::uint32_t> stopped;
  for (const auto& [seq, unused] : book_.sequences)
    if (seq > id) stopped.push_back(seq);
  for (std::uint32_t seq : stopped) stopSequence(seq, false);
  TclError reported(error->code(), "session " + name_ + ": " + refusal_->what() +
                                       (stopped.empty() ? std::string() : "; the render sent after it was stopped") +
                                       "; renders fail until the next set");
  return reported;
}

}  // namespace pvr::tcl
