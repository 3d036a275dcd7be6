# Sourced by bench shell scripts: median_of prints the median of the
# numbers on its input (separated by spaces or newlines; nothing for none).
median_of() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { if (NR) print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
