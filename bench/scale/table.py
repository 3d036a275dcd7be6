"""The text table of bench/scale: every row of the CSV run.sh wrote, and
the issue 11 ratios (first frame against the file's read time).

    /usr/bin/python3 bench/scale/table.py RESULTS.csv > RESULTS.txt
"""
import csv
import sys

PHASES = ("start", "read", "prep", "dist", "rend", "comp", "comm", "send", "write")


def num(row, key):
    return float(row[key]) if row.get(key) not in (None, "") else None


def fmt(v, spec="%.3f"):
    return spec % v if v is not None else "-"


def main(path):
    rows = list(csv.DictReader(open(path)))
    reads = {r["cache"]: num(r, "wall_s") for r in rows if r["kind"] == "read"}
    voxels = next((int(r["voxels"]) for r in rows if r["kind"] == "read"), None)
    if voxels:
        gib = voxels / 2**30
        print("volume: %d voxels uint8 (%.2f GiB); sequential read: cold %s s (%.0f MB/s), warm %s s (%.0f MB/s)"
              % (voxels, gib, fmt(reads.get("cold")), voxels / 1e6 / reads["cold"], fmt(reads.get("warm")),
                 voxels / 1e6 / reads["warm"]))
    print()
    head = ["kind", "ranks", "cache", "wall_s", "x_read"] + list(PHASES) + ["fps", "rss_max_mb", "rss_mb_per_rank"]
    print("%-15s %5s %5s %8s %6s" % tuple(head[:5]) + "".join(" %7s" % h for h in PHASES) +
          " %7s %10s  %s" % tuple(head[-3:]))
    for r in rows:
        if r["kind"] == "read":
            continue
        wall, readfile = num(r, "wall_s"), num(r, "read_file_s")
        ratio = wall / readfile if wall and readfile else None
        print("%-15s %5s %5s %8s %6s" % (r["kind"], r["ranks"], r["cache"], fmt(wall), fmt(ratio, "%.2f")) +
              "".join(" %7s" % fmt(num(r, p)) for p in PHASES) +
              " %7s %10s  %s" % (fmt(num(r, "fps"), "%.2f") if r["kind"] != "batch" else "-",
                                 r["rss_max_mb"] or "-", r["rss_mb_per_rank"]))
    print()
    # Issue 11's targets on 8 ranks: cold within 1.5x the cold read; warm
    # within 1.2x the warm read plus one frame (the warm run's rend, comp,
    # comm, send and write).
    for kind in ("batch", "pvrsh"):
        by = {r["cache"]: r for r in rows if r["kind"] == kind and r["ranks"] == "8"}
        if "cold" in by and reads.get("cold"):
            print("%s, 8 ranks, cold: first frame %.3f s = %.2fx the cold read (target <= 1.5x)"
                  % (kind, num(by["cold"], "wall_s"), num(by["cold"], "wall_s") / reads["cold"]))
        # warm: the page cache; summaries: the page cache and the brick
        # summaries (run.sh --summaries).
        for cache in ("warm", "summaries"):
            if cache in by and reads.get("warm"):
                frame = sum(num(by[cache], p) or 0 for p in ("rend", "comp", "comm", "send", "write"))
                print("%s, 8 ranks, %s: first frame %.3f s = %.2fx the warm read plus one frame (%.3f s; target <= 1.2x)"
                      % (kind, cache, num(by[cache], "wall_s"), num(by[cache], "wall_s") / (reads["warm"] + frame),
                         reads["warm"] + frame))
    series = {r["kind"]: r for r in rows if r["kind"].startswith("series-")}
    if series:
        print("series: %s" % ", ".join("%s %s fps" % (k, fmt(num(r, "fps"), "%.2f")) for k, r in sorted(series.items())))
        # The work of a frame, summed over the ranks (older results lack it):
        # beside the static one it is what each step costs on top.
        if any(num(r, "cpu_s_frame") for r in series.values()):
            static = num(series["series-static"], "cpu_s_frame") if "series-static" in series else None
            print("series CPU s per frame over the ranks: %s" % ", ".join(
                "%s %s%s" % (k, fmt(num(r, "cpu_s_frame")),
                             " (%.2fx static)" % (num(r, "cpu_s_frame") / static)
                             if static and num(r, "cpu_s_frame") and k != "series-static" else "")
                for k, r in sorted(series.items())))
            if static:
                for k, r in sorted(series.items()):
                    if k != "series-static" and num(r, "fps") and num(series["series-static"], "fps"):
                        print("%s: %.0f %% of the static frame rate" % (k, 100 * num(r, "fps") / num(series["series-static"], "fps")))


if __name__ == "__main__":
    main(sys.argv[1])
