#include "dataset_names.h"

#include <algorithm>
#include <numeric>

namespace pvr::daemon {

std::size_t editDistance(const std::string& a, const std::string& b) {
  // One row of the dynamic programme at a time: row[j] is the distance
  // from a's first i characters to b's first j.
  std::vector<std::size_t> row(b.size() + 1);
  std::iota(row.begin(), row.end(), std::size_t(0));
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::vector<std::string> closestNames(const std::string& name, const std::vector<std::string>& names,
                                      std::size_t most) {
  std::vector<std::pair<std::size_t, std::size_t>> scored;  // (distance, index)
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string& n = names[i];
    // Alike: the whole names are within half the longer's length plus one
    // edit; or `name` starts or ends the longer name (one edit away); or it
    // is a start typed with at most a third of its letters wrong ("ct_haed"
    // for "ct_head_cranium"), one edit more than that start's distance.
    std::size_t d = editDistance(name, n);
    bool alike = d <= std::max(name.size(), n.size()) / 2 + 1;
    if (!name.empty() && n.size() > name.size()) {
      if (n.compare(0, name.size(), name) == 0 || n.compare(n.size() - name.size(), name.size(), name) == 0) {
        d = 1;
        alike = true;
      } else if (const std::size_t start = editDistance(name, n.substr(0, name.size())); start <= name.size() / 3) {
        d = std::min(d, start + 1);
        alike = true;
      }
    }
    if (alike) scored.push_back({d, i});
  }
  std::stable_sort(scored.begin(), scored.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<std::string> out;
  for (std::size_t k = 0; k < scored.size() && k < most; ++k) out.push_back(names[scored[k].second]);
  return out;
}

std::optional<std::string> fileOfStem(const std::vector<proto::CatalogEntry>& catalog, const std::string& name) {
  for (const proto::CatalogEntry& e : catalog)
    if (e.name == name) return e.file;
  return std::nullopt;
}

std::string unknownDatasetText(const std::string& name, const std::vector<proto::CatalogEntry>& catalog) {
  std::vector<std::string> names;
  for (const proto::CatalogEntry& e : catalog) names.push_back(e.name);
  const std::vector<std::string> close = closestNames(name, names);
  std::string text = "no dataset '" + name + "' in the catalog";
  for (std::size_t i = 0; i < close.size(); ++i)
    text += (i == 0 ? "; did you mean '" : i + 1 == close.size() ? "' or '" : "', '") + close[i];
  if (!close.empty()) text += "'?";
  return text;
}

}  // namespace pvr::daemon
