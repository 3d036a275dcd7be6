// The pure parts of pvrd: the catalog (with stand-in node programs), dataset names, options, the advertised
// address, mpirun messages.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>
#include <variant>

#include "../proc_files.h"
#include "advertise.h"
#include "auth.h"
#include "catalog.h"
#include "options.h"
#include "mpirun_launcher.h"
#include "sys.h"

namespace fs = std::filesystem;
using namespace pvr::daemon;
using pvr::proto::ErrorCode;

namespace {

fs::path makeDataDir() {
  const fs::path root = fs::path(PVR_TEST_TMP) / ("catalog_" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root / "sub");
  fs::create_directories(root / "outside");
  std::ofstream(root / "a.json") << "{}";
  std::ofstream(root / "b.nhdr") << "x";
  std::ofstream(root / "notes.txt") << "x";
  std::ofstream(root / "sub" / "sub.nii.gz") << "x";
  std::ofstream(root / "outside" / "secret.json") << "{}";
  fs::create_directories(root / "data");
  fs::rename(root / "a.json", root / "data" / "a.json");
  fs::rename(root / "b.nhdr", root / "data" / "b.nhdr");
  fs::rename(root / "notes.txt", root / "data" / "notes.txt");
  fs::rename(root / "sub", root / "data" / "sub");
  fs::create_symlink(root / "outside" / "secret.json", root / "data" / "link.json");
  fs::create_directory_symlink(root / "outside", root / "data" / "linkdir");
  return root / "data";
}

ErrorCode codeOf(const std::variant<std::string, pvr::proto::ProtocolError>& r) {
  return std::get<pvr::proto::ProtocolError>(r).code;
}

}  // namespace

namespace {

// A stand-in for `pvr-node --catalog DIR`: a shell script in the test's
// scratch directory (the real program is run by the process tests).
std::string fakeNode(const std::string& name, const std::string& body) {
  const fs::path dir = fs::path(PVR_TEST_TMP) / ("fake_node_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / name;
  std::ofstream(path) << "#!/bin/sh\n" << body << "\n";
  fs::permissions(path, fs::perms::owner_all);
  return path.string();
}

using Listed = std::variant<std::vector<pvr::proto::CatalogEntry>, pvr::proto::ProtocolError>;

pvr::proto::ProtocolError errorOf(const Listed& r) {
  REQUIRE(std::holds_alternative<pvr::proto::ProtocolError>(r));
  return std::get<pvr::proto::ProtocolError>(r);
}

// The process whose pid `pidFile` holds is gone or a zombie (dead, waiting
// for whichever process adopted it to reap it).
// True once the process whose pid `pidFile` holds is gone or a zombie,
// within 5 s: a killed process lingers a moment on a loaded machine.
bool processGone(const fs::path& pidFile) {
  std::ifstream in(pidFile);
  pid_t pid = 0;
  in >> pid;
  REQUIRE(pid > 0);
  for (int tries = 0; tries < 250; ++tries) {
    if (!pvr::testing::processRuns(pid)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

}  // namespace

TEST_CASE("the catalog is the node program's dataset lines, its other lines are notes") {
  std::vector<std::string> notes;
  const auto listed = listDatasets(
      fakeNode("lists", "echo 'pvr-node --catalog: left out bad.json: not JSON' >&2\n"
                        "printf '1\\tball\\tball/ball.json\\traw+json\\t32\\t32\\t32\\tuint8\\t\\n"
                        "50\\truns/run\\truns/run.series.json\\tseries\\t8\\t8\\t4\\tfloat32\\t\\n"
                        "1\\twide\\twide.nhdr\\tnrrd\\t0\\t0\\t0\\t\\tcannot be loaded: double\\n'\n"
                        "test \"$1 $2\" = \"--catalog /the/dir\" || echo 'wrong arguments' >&2"),
      "/the/dir", 10, [&](const std::string& n) { notes.push_back(n); });
  REQUIRE(std::holds_alternative<std::vector<pvr::proto::CatalogEntry>>(listed));
  CHECK(std::get<0>(listed) ==
        std::vector<pvr::proto::CatalogEntry>{{"ball", 1, "ball/ball.json", "raw+json", {32, 32, 32}, "uint8", ""},
                                              {"runs/run", 50, "runs/run.series.json", "series", {8, 8, 4}, "float32", ""},
                                              {"wide", 1, "wide.nhdr", "nrrd", {0, 0, 0}, "", "cannot be loaded: double"}});
  CHECK(notes == std::vector<std::string>{"pvr-node --catalog: left out bad.json: not JSON"});
}

TEST_CASE("a catalog program that fails, is missing or prints nonsense gives an error naming it") {
  const auto ignore = [](const std::string&) {};
  const auto failing = errorOf(listDatasets(fakeNode("fails", "echo 'pvr-node --catalog: /d: no such directory' >&2\nexit 3"),
                                            "/d", 10, ignore));
  CHECK(failing.code == ErrorCode::kIo);
  CHECK_THAT(failing.text, Catch::Contains("cannot list the catalog") && Catch::Contains("fails --catalog /d") &&
                               Catch::Contains("exited with status 3: pvr-node --catalog: /d: no such directory"));

  const auto missing = errorOf(listDatasets("/nonexistent/pvr-node", "/d", 10, ignore));
  CHECK(missing.code == ErrorCode::kIo);
  CHECK_THAT(missing.text, Catch::Contains("/nonexistent/pvr-node --catalog /d") && Catch::Contains("status 127"));

  const auto garbled = errorOf(listDatasets(fakeNode("garbled", "printf '12x\\tname\\tname.json\\traw+json\\t1\\t1\\t1\\tuint8\\t\\n'"), "/d", 10, ignore));
  CHECK_THAT(garbled.text, Catch::Contains("malformed line '12x\\x09name"));
  const auto zero = errorOf(listDatasets(fakeNode("zero", "printf '0\\tname\\tname.json\\traw+json\\t1\\t1\\t1\\tuint8\\t\\n'"), "/d", 10, ignore));
  CHECK_THAT(zero.text, Catch::Contains("malformed line"));
}

// Issue 15, finding 15: a catalog over 4 MiB was sent, and the client
// (which must refuse it) lost its session. 40000 names of 131 bytes make a
// reply of 7.0 MB (with each entry's file, format, dims and type); the limit is 4 MiB.
TEST_CASE("a catalog reply over the protocol's limit is refused with LIMIT_EXCEEDED naming its size and the limit") {
  const auto big = errorOf(listDatasets(
      fakeNode("big", "awk 'BEGIN { for (i = 0; i < 40000; i++) printf \"1\\td%0125d\\td.json\\tf\\t1\\t1\\t1\\tuint8\\t\\n\", i }'"), "/d", 20,
      [](const std::string&) {}));
  CHECK(big.code == ErrorCode::kLimitExceeded);
  CHECK_THAT(big.text, Catch::Contains("the catalog of 40000 datasets is 6960004 bytes, over the protocol's limit of "
                                       "4194304 bytes for a catalog reply"));
  // One that fits still lists.
  const std::vector<pvr::proto::CatalogEntry> fits(1000, {std::string(100, 'd'), 1});
  CHECK_FALSE(checkCatalogSize(fits));
}

TEST_CASE("a catalog program over its time limit is killed with its children and reported") {
  // 2 s: time for the script to write both pid files even on a loaded
  // machine (0.5 s failed once while a build ran beside it).
  const fs::path pids = fs::path(PVR_TEST_TMP) / ("slow_catalog_" + std::to_string(::getpid()));
  const auto slow = errorOf(listDatasets(
      fakeNode("slow", "echo $$ > " + pids.string() + ".sh\nsleep 60 &\necho $! > " + pids.string() + ".sleep\nwait"),
      "/d", 2.0, [](const std::string&) {}));
  CHECK(slow.code == ErrorCode::kTimeout);
  CHECK_THAT(slow.text, Catch::Contains("did not finish in 2 s"));
  CHECK(processGone(pids.string() + ".sh"));
  CHECK(processGone(pids.string() + ".sleep"));
}

TEST_CASE("dataset names resolve inside the data directory only") {
  const fs::path dir = makeDataDir();
  const auto ok = resolveDataset(dir.string(), "sub/sub.nii.gz");
  REQUIRE(std::holds_alternative<std::string>(ok));
  CHECK(std::get<std::string>(ok) == fs::canonical(dir / "sub" / "sub.nii.gz").string());
  CHECK(codeOf(resolveDataset(dir.string(), "../outside/secret.json")) == ErrorCode::kBadArgument);
  CHECK(codeOf(resolveDataset(dir.string(), "sub/../../outside/secret.json")) == ErrorCode::kBadArgument);
  CHECK(codeOf(resolveDataset(dir.string(), (dir / "a.json").string())) == ErrorCode::kBadArgument);
  CHECK(codeOf(resolveDataset(dir.string(), "link.json")) == ErrorCode::kDatasetNotFound);
  CHECK(codeOf(resolveDataset(dir.string(), "linkdir/secret.json")) == ErrorCode::kDatasetNotFound);
  CHECK(codeOf(resolveDataset(dir.string(), "missing.json")) == ErrorCode::kDatasetNotFound);
  CHECK(codeOf(resolveDataset(dir.string(), "sub")) == ErrorCode::kDatasetNotFound);  // a directory
  // Whether a file is a volume is the node's to say when it opens it.
  CHECK(std::holds_alternative<std::string>(resolveDataset(dir.string(), "notes.txt")));
  CHECK(codeOf(resolveDataset(dir.string(), "")) == ErrorCode::kBadArgument);
}

TEST_CASE("options parse listen address, limits and refuse a public bind without a token") {
  std::string error;
  auto o = parseOptions({"--listen", "127.0.0.1:0", "--data-dir", "/d", "--max-ranks", "3", "--idle-timeout", "5"}, error);
  REQUIRE(o);
  CHECK(o->host == "127.0.0.1");
  CHECK(o->port == 0);
  CHECK(o->maxRanks == 3);
  CHECK(o->idleTimeout == 5);
  CHECK(o->handshakeTimeout == 10);
  o = parseOptions({"--data-dir", "/d", "--max-unauthenticated", "3", "--max-connections", "9", "--handshake-timeout", "2"},
                   error);
  REQUIRE(o);
  CHECK(o->maxUnauthenticated == 3);
  CHECK(o->maxConnections == 9);
  CHECK(o->handshakeTimeout == 2);
  CHECK_FALSE(parseOptions({"--data-dir", "/d", "--max-unauthenticated", "0"}, error));
  CHECK(parseOptions({"--data-dir", "/d", "--stall-timeout", "5"}, error)->stallTimeout == 5);
  CHECK_FALSE(parseOptions({"--data-dir", "/d", "--stall-timeout", "1"}, error));
  CHECK(error == "--stall-timeout takes seconds from 2 to 86400, not '1'");
  CHECK_FALSE(parseOptions({"--listen", "0.0.0.0:7000", "--data-dir", "/d"}, error));
  CHECK(error.find("token") != std::string::npos);
  CHECK(parseOptions({"--listen", "0.0.0.0:7000", "--data-dir", "/d", "--token-file", "/t"}, error));
  CHECK_FALSE(parseOptions({"--listen", "127.0.0.1:99999", "--data-dir", "/d"}, error));
  CHECK_FALSE(parseOptions({"--listen", "127.0.0.1:1", "--data-dir", "/d", "--max-ranks", "-1"}, error));
  CHECK_FALSE(parseOptions({"--listen", "127.0.0.1:1"}, error));
  CHECK_FALSE(parseOptions({"--data-dir", "/d", "--bogus", "1"}, error));
}

TEST_CASE("loopback is decided on the addresses a listen name resolves to, not on its spelling") {
  for (const char* host : {"127.0.0.1", "127.0.0.2", "127.1", "::1", "localhost"}) {
    INFO(host);
    CHECK(isLoopback(host));
  }
  // A name that only starts like loopback, the wildcard, a public address,
  // a v4-mapped public address, nothing.
  for (const char* host : {"127.attacker", "127.0.0.1.example.invalid", "0.0.0.0", "::", "192.0.2.1",
                           "::ffff:192.0.2.1", ""}) {
    INFO(host);
    CHECK_FALSE(isLoopback(host));
  }
  std::string error;
  CHECK_FALSE(parseOptions({"--listen", "127.attacker:7000", "--data-dir", "/d"}, error));
  CHECK(error == "refusing to listen on 127.attacker without --token-file (see docs/pvrd.md)");
}

TEST_CASE("options: --advertise takes numeric IPv4, --launcher a known name, slurm's options need slurm") {
  std::string error;
  auto o = parseOptions({"--data-dir", "/d", "--advertise", "10.213.7.10", "--launcher", "slurm", "--partition", "vis",
                         "--time", "30", "--salloc", "/x/salloc", "--scancel", "/x/scancel"},
                        error);
  REQUIRE(o);
  CHECK(o->advertise == "10.213.7.10");
  CHECK(o->launcher == "slurm");
  CHECK(o->partition == "vis");
  CHECK(o->time == "30");
  CHECK(o->salloc == "/x/salloc");
  CHECK(o->scancel == "/x/scancel");
  CHECK(parseOptions({"--data-dir", "/d"}, error)->launcher == "mpirun");
  CHECK_FALSE(parseOptions({"--data-dir", "/d", "--advertise", "h0"}, error));
  CHECK(error == "--advertise takes a numeric IPv4 address, not 'h0'");
  CHECK_FALSE(parseOptions({"--data-dir", "/d", "--launcher", "pbs"}, error));
  CHECK(error == "--launcher takes one of mpirun, slurm, not 'pbs'");
  CHECK_FALSE(parseOptions({"--data-dir", "/d", "--partition", "vis"}, error));
  CHECK(error == "--partition and --time need --launcher slurm");
  CHECK_FALSE(parseOptions({"--data-dir", "/d", "--launcher", "slurm", "--hostfile", "/h"}, error));
  CHECK_THAT(error, Catch::StartsWith("--hostfile does not go with --launcher slurm"));
}

TEST_CASE("the first host of a hostfile: first word of the first line with one, no user, no comment") {
  CHECK(firstHostfileHost("# cluster\n\n  h1 slots=2 max_slots=4\nh2 slots=2\n") == "h1");
  CHECK(firstHostfileHost("pvr@10.213.7.11 slots=1") == "10.213.7.11");
  CHECK(firstHostfileHost("h3# a comment right after") == "h3");
  CHECK(firstHostfileHost("# nothing\n   \n") == "");
}

TEST_CASE("the advertised address: the option, else the route towards the first hostfile host, else loopback") {
  std::string error;
  DaemonOptions o;
  CHECK(advertiseAddress(o, error) == "127.0.0.1");
  o.advertise = "10.213.7.10";
  CHECK(advertiseAddress(o, error) == "10.213.7.10");
  o.advertise.clear();
  const fs::path hostfile = fs::path(PVR_TEST_TMP) / ("hostfile_" + std::to_string(::getpid()));
  fs::create_directories(hostfile.parent_path());
  std::ofstream(hostfile) << "# loopback hosts\nlocalhost slots=2\n";
  o.hostfile = hostfile.string();
  // The route to a loopback host leaves from loopback.
  CHECK(advertiseAddress(o, error) == "127.0.0.1");
  CHECK(routeSourceAddress("127.0.0.2", error) == "127.0.0.1");
  o.hostfile = (hostfile.string() + ".missing");
  CHECK(advertiseAddress(o, error).empty());
  CHECK_THAT(error, Catch::StartsWith("cannot read hostfile "));
  std::ofstream(hostfile) << "no-such-host.invalid\n";
  o.hostfile = hostfile.string();
  CHECK(advertiseAddress(o, error).empty());
  CHECK_THAT(error, Catch::Contains("no-such-host.invalid") && Catch::Contains("--advertise"));
}

TEST_CASE("the failed rank is read from mpirun's message") {
  CHECK(rankFromMpirunOutput("mpirun noticed that process rank 1 with PID 4242 on node x exited on signal 9 (Killed).") == 1);
  CHECK(rankFromMpirunOutput("something else") == -1);
}

TEST_CASE("a host Open MPI lost contact with is named in the job's end text") {
  // Open MPI 4.1's words when a remote daemon vanishes (ORTE help text).
  const std::string lostDaemon =
      "--------------------------------------------------------------------------\n"
      "ORTE has lost communication with a remote daemon.\n\n"
      "  HNP daemon   : [[41029,0],0] on node h0\n"
      "  Remote daemon: [[41029,0],2] on node h2\n\n"
      "This is usually due to either a failure of the TCP network\n";
  CHECK(lostHostFromMpirunOutput(lostDaemon) == "h2");
  CHECK(lostHostFromMpirunOutput("  Local host: h1\n  Peer host:  h3\n") == "h3");
  // A rank that cannot reach the lost host's ranks names its address; the
  // resolver turns it into a name where it can (here the hosts file's
  // 127.0.0.1), and an address nobody names stays an address.
  CHECK(lostHostFromMpirunOutput("  Local host: h3\n  Message:    connect() to 127.0.0.1:1024 failed\n") == "localhost");
  CHECK(lostHostFromMpirunOutput("  Message:    connect() to 192.0.2.77:1024 failed\n") == "192.0.2.77");
  // ssh noticing first: its line, then ORTE's generic block (one run in
  // five of tests/cluster/host_lost.sh).
  CHECK(lostHostFromMpirunOutput("Connection to 192.0.2.78 closed by remote host.\n"
                                 "--------------------------------------------------------------------------\n"
                                 "ORTE was unable to reliably start one or more daemons.\n") == "192.0.2.78");
  CHECK(lostHostFromMpirunOutput("Connection to 127.0.0.1 closed by remote host.\n") == "localhost");
  CHECK(lostHostFromMpirunOutput("mpirun noticed that process rank 1 with PID 4242 on node x exited") == "");
  const std::string text = mpirunEndText("mpirun exited with status 1", lostDaemon);
  CHECK_THAT(text, Catch::StartsWith("host h2 was lost"));
  CHECK_THAT(text, Catch::Contains("mpirun exited with status 1"));
}
