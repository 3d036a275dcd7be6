#!/bin/bash
# `cmake --install` into a temporary prefix (issue 14, point 7): every
# executable in bin, the man pages where man finds them, package pvr where
# the installed pvrsh loads it (not the build tree's), the GUI's scripts
# where examples/gui.tcl finds them, and the installed tools working: a
# volume made by pvr-make-volume rendered by pvr-render straight from its
# file (.json sidecar and .nhdr) into a PNG whose centre shows the volume
# over a black background.
#   install_test.sh BUILD_DIR TMP_DIR
set -eu
build=$1
prefix=$2/install_prefix
rm -rf "$prefix"
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

cmake --install "$build" --prefix "$prefix" >/dev/null

for program in pvrd pvr-node pvrsh pvr-render pvr-make-volume; do
  [ -x "$prefix/bin/$program" ] || fail "bin/$program is not installed"
  "$prefix/bin/$program" --help >/dev/null || fail "installed $program --help fails"
done
for page in pvrsh pvrd pvr-render pvr-node; do
  [ -f "$prefix/share/man/man1/$page.1" ] || { fail "share/man/man1/$page.1 is not installed"; continue; }
  text=$(MANPATH="$prefix/share/man" MANPAGER=cat MANWIDTH=100 man "$page" 2>&1) || fail "man $page: $text"
  grep -q "SYNOPSIS" <<<"$text" && grep -q "EXAMPLE" <<<"$text" || fail "man $page has no SYNOPSIS or EXAMPLE"
done

# The installed pvrsh loads the installed package, and help works in it.
loaded=$(env -u TCLLIBPATH "$prefix/bin/pvrsh" -nogui <<'TCL'
puts [package ifneeded pvr [package require pvr]]
puts [lindex [split [pvr_session help wait] \n] 0]
TCL
)
grep -q "$prefix/lib/pvr" <<<"$loaded" || fail "installed pvrsh loads package pvr from elsewhere: $loaded"
grep -q "^NAME wait ?-timeout seconds?" <<<"$loaded" || fail "pvr_session help in the installed pvrsh: $loaded"
[ -f "$prefix/share/pvr/tcl/gui.tcl" ] || fail "share/pvr/tcl/gui.tcl is not installed"
[ -f "$prefix/share/pvr/examples/gui.tcl" ] || fail "share/pvr/examples/gui.tcl is not installed"
grep -q 'source \[file join \[file dirname \[file normalize \[info script\]\]\] .. tcl gui.tcl\]' \
  "$prefix/share/pvr/examples/gui.tcl" || fail "examples/gui.tcl no longer finds ../tcl/gui.tcl"

# pvr-render straight from volume files, with the installed tools only.
data=$2/install_data
rm -rf "$data"
sidecar=$("$prefix/bin/pvr-make-volume" shepp-logan 40 "$data")
raw=${sidecar%.json}.raw
cat > "${sidecar%.json}.nhdr" <<NHDR
NRRD0004
type: float
dimension: 3
sizes: 40 40 40
endian: little
encoding: raw
data file: $(basename "$raw")
NHDR
for volume in "$sidecar" "${sidecar%.json}.nhdr"; do
  png=$data/$(basename "$volume").png
  "$prefix/bin/pvr-render" "$volume" -o "$png" --size 64x64 >/dev/null || { fail "pvr-render $volume"; continue; }
  # Centre pixel lit (the ramp shows the phantom), corner the black background.
  /usr/bin/python3 - "$png" <<'PY' || fail "pvr-render $volume: the image is not the volume over black"
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()
pos, idat, w, h = 8, b"", 0, 0
while pos < len(data):
    n, kind = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    if kind == b"IHDR": w, h, depth, colour = struct.unpack(">IIBB", body[:10])
    if kind == b"IDAT": idat += body
    pos += 12 + n
bpp = {2: 3, 6: 4}[colour]
raw, rows, prev = zlib.decompress(idat), [], bytearray(w * bpp)
for y in range(h):
    f, line = raw[y * (w * bpp + 1)], bytearray(raw[y * (w * bpp + 1) + 1:(y + 1) * (w * bpp + 1)])
    for i in range(len(line)):
        a = line[i - bpp] if i >= bpp else 0
        b, c = prev[i], prev[i - bpp] if i >= bpp else 0
        p = a + b - c
        pred = [0, a, b, (a + b) // 2, a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c) else (b if abs(p - b) <= abs(p - c) else c)][f]
        line[i] = (line[i] + pred) & 255
    rows.append(line); prev = line
centre, corner = rows[h // 2][w // 2 * bpp], rows[0][0]
print("centre", centre, "corner", corner)
sys.exit(0 if centre > 40 and corner == 0 else 1)
PY
done
[ $failures -eq 0 ] && echo "ok: installed into $prefix"
exit $((failures > 0))
