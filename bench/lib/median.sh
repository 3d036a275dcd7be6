# Sourced by bench shell scripts: median_of prints the median of the
# numbers on its input (separated by spaces or newlines; nothing for none).
# It succeeds on empty input too (awk, not grep, drops the empty lines), so
# that a script under set -euo pipefail goes on without the figure, as
# run.sh does when VTK is not measured.
median_of() { tr ' ' '\n' | awk 'NF' | sort -g | awk '{ v[NR] = $1 } END { if (NR) print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
