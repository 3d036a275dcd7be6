#include "salloc_output.h"

#include <regex>

namespace pvr::daemon {
namespace {

struct Pattern {
  std::regex re;  // group 1, when present, is the job id
  SallocLine::Kind kind;
  const char* reason;  // nullptr: the whole message is the reason
};

// Message formats of salloc 22.05 (strings of /usr/bin/salloc and
// libslurmfull on Debian 12), after the "salloc: " prefix and any
// "error: " level.
const std::vector<Pattern>& patterns() {
  using K = SallocLine::Kind;
  static const std::vector<Pattern> table = [] {
    std::vector<Pattern> t;
    const auto add = [&](const char* re, K kind, const char* reason) { t.push_back({std::regex(re), kind, reason}); };
    add(R"(Pending job allocation (\d+))", K::kQueued, "pending");
    add(R"(job (\d+) queued and waiting for resources)", K::kQueued, "queued and waiting for resources");
    add(R"(job (\d+) has been allocated resources)", K::kGranted, "allocated resources");
    add(R"(Granted job allocation (\d+))", K::kGranted, "granted");
    add(R"(Job allocation (\d+) has been revoked\.?)", K::kRevoked, nullptr);
    add(R"(Job (\d+) has exceeded its time limit and its allocation has been revoked\.?)", K::kRevoked, nullptr);
    add(R"(Allocation was revoked for job (\d+) before command could be run)", K::kRevoked, nullptr);
    add(R"(Job has been cancelled)", K::kRevoked, nullptr);
    add(R"(Relinquishing job allocation (\d+))", K::kReleased, "released");
    return t;
  }();
  return table;
}

bool consume(std::string_view& text, std::string_view prefix) {
  if (text.substr(0, prefix.size()) != prefix) return false;
  text.remove_prefix(prefix.size());
  return true;
}

}  // namespace

std::optional<SallocLine> parseSallocLine(std::string_view line) {
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
  if (!consume(line, "salloc: ")) return std::nullopt;
  const bool error = consume(line, "error: ") || consume(line, "fatal: ");
  const std::string message(line);
  for (const Pattern& p : patterns()) {
    std::smatch m;
    if (!std::regex_match(message, m, p.re)) continue;
    return SallocLine{p.kind, m.size() > 1 ? m[1].str() : std::string(), p.reason ? p.reason : message};
  }
  if (error) return SallocLine{SallocLine::Kind::kError, {}, message};
  return std::nullopt;
}

std::optional<LaunchEvent> SallocMonitor::onLine(std::string_view text) {
  const auto line = parseSallocLine(text);
  if (!line) return std::nullopt;
  if (!line->job.empty()) job_ = line->job;
  using K = SallocLine::Kind;
  switch (line->kind) {
    case K::kQueued:
      return LaunchEvent{LaunchEvent::Kind::kQueued, job_, line->reason};
    case K::kGranted:
      granted_ = true;
      return LaunchEvent{LaunchEvent::Kind::kGranted, job_, line->reason};
    case K::kRevoked:
      if (revoked_.empty()) revoked_ = line->reason;
      return LaunchEvent{LaunchEvent::Kind::kLost, job_, line->reason};
    case K::kReleased:
      released_ = true;
      return std::nullopt;
    case K::kError:
      lastError_ = line->reason;
      return std::nullopt;
  }
  return std::nullopt;
}

std::optional<std::string> SallocMonitor::failureText(const std::string& why) const {
  if (granted_ && revoked_.empty()) return std::nullopt;
  const std::string reason = !revoked_.empty() ? revoked_ : !lastError_.empty() ? lastError_ : why;
  return "slurm: allocation " + (job_.empty() ? std::string() : job_ + " ") + "failed: " + reason;
}

}  // namespace pvr::daemon
