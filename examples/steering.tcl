# Computational steering (docs/steering.md): the Gray-Scott reaction-diffusion
# example runs on the ranks and is rendered every 10 steps with nothing
# written to disk between; after 200 steps the feed rate is raised, and the
# pattern changes from the next frame on. Frames go to OUTDIR as PNG files
# (and to a Tk window when there is a display).
#
#   pvrsh examples/steering.tcl ?HOST:PORT? ?OUTDIR?
#
# HOST:PORT: first argument, else $PVR_SERVER, else 127.0.0.1:7350.
set host [expr {[llength $argv] > 0 ? [lindex $argv 0] :
                [info exists env(PVR_SERVER)] ? $env(PVR_SERVER) : "127.0.0.1:7350"}]
set out [expr {[llength $argv] > 1 ? [lindex $argv 1] : "steering-out"}]
file mkdir $out

pvr_session :gs
if {![catch {package present Tk}] && ![catch {winfo exists .}]} {
    image create photo gsImage
    pack [label .gs -image gsImage]
    :gs image window gsImage
}
:gs image file [file join $out gs.png]
:gs open $host -ranks 2
# v below 0.02 is clear: diffusion spreads tiny values everywhere.
:gs set -computation gray-scott,96,96,96 -imagesz 400,400 -shading 1 \
    -tf {0 0 0 0 0  0.02 0 0 0 0  0.1 0.2 0.5 1 0.2  0.3 1 0.9 0.4 0.9}
:gs render steps 200 -every 10
:gs wait -timeout 3600
puts "step [dict get [:gs list status] remote step]: [dict get [:gs list status] remote parameters]"
:gs set -param feed 0.045 -param kill 0.062
:gs render steps 200 -every 10
:gs wait -timeout 3600
puts "step [dict get [:gs list status] remote step]: [dict get [:gs list status] remote parameters]"
:gs close
if {[catch {package present Tk}]} { exit }
