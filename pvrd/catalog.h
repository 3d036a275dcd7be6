// The data catalog: datasets are named relative to --data-dir, never pathed.
//
// What a dataset is (which files, which formats, a time series once with
// its steps) is the renderer's format registry's to say, and pvrd links no
// renderer: the catalog is what `pvr-node --catalog DIR` prints
// (node/catalog_listing.h), run here with a time limit. pvrd itself only
// resolves names a client sends, keeping them inside the directory.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "pvr_protocol.h"

namespace pvr::daemon {

// How long a catalog listing may take before it is killed. It opens every
// dataset's headers (a series: every step's), normally well under a second;
// the session does not relay meanwhile.
inline constexpr double kCatalogSeconds = 20;

// Runs `nodePath --catalog dataDir` and parses its dataset lines
// (node/catalog_listing.h, printCatalog).
// Its other lines (files it left out and why) go to `note`. Returns the
// entries in the program's order (sorted by name), or the error for the
// client: kIo when the program cannot start, fails or prints a malformed
// line, kTimeout (the program killed) when it runs longer than
// `timeoutSeconds`, kLimitExceeded when the reply would be larger than a
// client accepts (checkCatalogSize). Nothing it started is left running.
std::variant<std::vector<proto::CatalogEntry>, proto::ProtocolError> listDatasets(
    const std::string& nodePath, const std::string& dataDir, double timeoutSeconds,
    const std::function<void(const std::string&)>& note);

// kLimitExceeded, naming the datasets, the bytes and the limit, when a
// CatalogReply of `entries` would be over the protocol's payload limit for
// it (protocol Limits, message_table.h's payloadLimit); nullopt when it fits.
std::optional<proto::ProtocolError> checkCatalogSize(const std::vector<proto::CatalogEntry>& entries);

// The real path of dataset `name` inside `dataDir`, or the error to send:
// kBadArgument for an absolute name or one with a ".." component,
// kDatasetNotFound when it does not exist, is not a regular file, or
// resolves (symlinks included) outside the directory. Whether it is a
// volume the node says when it opens it.
std::variant<std::string, proto::ProtocolError> resolveDataset(const std::string& dataDir, const std::string& name);

}  // namespace pvr::daemon
