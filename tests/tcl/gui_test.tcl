# gui_test.tcl -- the PVR GUI against a real pvrd, driven with event generate.
#
#   xvfb-run -a pvrsh gui_test.tcl -pvrd PVRD -node PVR_NODE -source SRC -out DIR
#
# Starts pvrd on an ephemeral loopback port with a 32^3 volume that is not
# symmetric about any axis (an off-centre block and a ball), opens the GUI
# (tcl/gui.tcl) on it, and checks, by the photo's pixels:
#   1. the first frame arrives after connecting; the view starts from the
#      camera the server reports, the editor spans the data's value range;
#   2. a drag on the image turns the view, coalesces its motion events into
#      fewer requests, and changes the image;
#   3. a press of the "turn right" button turns it by 15 degrees, another
#      frame, equal to a second session's frame of the same camera set
#      explicitly (eye and up turned about the look-at point);
#   4. dragging a transfer-function point renders again, with other pixels;
#   5. a ParaView preset loaded through the GUI: the editor holds the points
#      the server read, and a frame renders with them;
#   6. a rotation sequence fills the progress bar and the performance graph;
#   7. the cluster and group window shows the layout, asks the server for
#      memory per cluster, applies the form, and its Strategy box offers
#      exactly the server's strategies, each of which renders without error;
#   5b. the mouse wheel zooms and the middle button pans the server's
#      camera, the +z button looks down z, Reset returns the automatic
#      camera; a screenshot of the screen shows the frame;
#   8. the time slider
#      is hidden for a single volume and shown for a series of 3 steps;
#      moving it sets the session's step and renders a new frame.
# Writes DIR/gui_frame.png (the photo) and DIR/gui_screenshot.png (the whole
# screen, when ImageMagick's import is installed). Exits 0 when all pass, 1
# otherwise; gives up after 140 s.

package require Tk

# ---- Options ----
array set arg {-pvrd "" -node "" -source "" -out .}
foreach {k v} $argv {
    set arg($k) $v
}
foreach k {-pvrd -node -source} {
    if {$arg($k) eq ""} {
        puts stderr "usage: gui_test.tcl -pvrd PVRD -node PVR_NODE -source SRC -out DIR"
        exit 2
    }
}
file mkdir $arg(-out)

source [file join [file dirname [info script]] gui_harness.tcl]
set pvrdChan ""

# finish: stops pvrd (SIGTERM: it ends its sessions and their MPI jobs) and exits.
proc finish {} {
    catch {:pvrgui close}
    if {$::pvrdChan ne ""} {
        foreach p [pid $::pvrdChan] {
            catch {exec kill -TERM $p}
        }
        catch {close $::pvrdChan}
    }
    puts [expr {$::failures == 0 ? "gui test passed" : "gui test: $::failures failures"}]
    exit [expr {$::failures == 0 ? 0 : 1}]
}

after 140000 {
    puts "FAIL timeout: the GUI test did not finish in 140 s"
    incr ::failures
    finish
}


# pvrtest_near: number lists A and B agree within 1e-9 element by element.
proc pvrtest_near {a b} {
    if {[llength $a] != [llength $b]} { return 0 }
    foreach x $a y $b {
        if {abs($x - $y) > 1e-9} { return 0 }
    }
    return 1
}

# ---- Step 1: data and pvrd ----
set data [file join $arg(-out) data]
file delete -force $data
file mkdir [file join $data block]
# Voxel (x,y,z), x fastest: 200 inside the block x 4..13, y 6..27, z 3..20,
# 120 inside the ball of radius 6 at (22, 20, 22), 0 elsewhere.
set bytes {}
for {set z 0} {$z < 32} {incr z} {
    for {set y 0} {$y < 32} {incr y} {
        set row {}
        for {set x 0} {$x < 32} {incr x} {
            set v 0
            if {$x >= 4 && $x <= 13 && $y >= 6 && $y <= 27 && $z >= 3 && $z <= 20} {
                set v 200
            } elseif {($x - 22) ** 2 + ($y - 20) ** 2 + ($z - 22) ** 2 <= 36} {
                set v 120
            }
            lappend row $v
        }
        append bytes [binary format c* $row]
    }
}
set f [open [file join $data block block.raw] wb]
puts -nonewline $f $bytes
close $f
set f [open [file join $data block block.json] w]
puts $f {{"dims": [32, 32, 32], "dtype": "uint8", "spacing": [1, 1, 1], "origin": [0, 0, 0],
 "raw_file": "block.raw", "endian": "little", "stats": {"min": 0, "max": 200}}}
close $f

# A series of 3 steps of the same grid: step k is the volume's values
# times 1 - 0.3 k (docs/scene.md, series sidecar).
file mkdir [file join $data blockseries]
binary scan $bytes cu* values
set steps {}
for {set k 0} {$k < 3} {incr k} {
    set f [open [file join $data blockseries step_$k.raw] wb]
    puts -nonewline $f [binary format c* [lmap v $values {expr {int($v * (1 - 0.3 * $k))}}]]
    close $f
    set f [open [file join $data blockseries step_$k.json] w]
    puts $f [format {{"dims": [32, 32, 32], "dtype": "uint8", "spacing": [1, 1, 1], "origin": [0, 0, 0], "raw_file": "step_%d.raw", "endian": "little"}} $k]
    close $f
    lappend steps [format {{"time": %d, "file": "step_%d.json"}} $k $k]
}
set f [open [file join $data blockseries blockseries.series.json] w]
puts $f "{\"series\": \[[join $steps {, }]\]}"
close $f

set env(OMPI_ALLOW_RUN_AS_ROOT) 1
set env(OMPI_ALLOW_RUN_AS_ROOT_CONFIRM) 1
# `timeout` ends pvrd even when this script is killed before finish runs.
set pvrdChan [open |[list timeout --signal=TERM 130 $arg(-pvrd) --listen 127.0.0.1:0 --data-dir $data --node $arg(-node) --max-ranks 2 2>@stderr] r]
fconfigure $pvrdChan -blocking 0 -buffering line
set port ""
proc readPvrd {} {
    if {[gets $::pvrdChan line] >= 0 && [regexp {listening on 127\.0\.0\.1:(\d+)} $line -> p]} {
        set ::port $p
    }
    if {[eof $::pvrdChan]} {
        fileevent $::pvrdChan readable {}
    }
}
fileevent $pvrdChan readable readPvrd
if {![waitFor {$::port ne ""} 10]} {
    check "pvrd starts" 0 "no 'pvrd listening on' line"
    finish
}

# Everything below runs inside one catch: an error fails the test and still
# stops pvrd (pvrsh stays in the event loop after a script error).
proc steps {} {
    uplevel #0 {
# ---- Step 2: the GUI and its first frame ----
source [file join $arg(-source) tcl gui.tcl]
set photo $::pvr::gui::image
::pvr::gui::main -host 127.0.0.1:$port -ranks 1 -dataset block -imagesz 128x128
update

# idle: no request in flight and none waiting.
proc idle {} {
    return [expr {!$::pvr::gui::view::busy && !$::pvr::gui::view::dirty && $::pvr::gui::view::pending == 0}]
}
# lit: pixels of the photo brighter than the dark background, in a 16x16 grid.
proc lit {} {
    set n 0
    set w [image width $::photo]
    set h [image height $::photo]
    for {set y 4} {$y < $h} {incr y [expr {max(1, $h / 16)}]} {
        for {set x 4} {$x < $w} {incr x [expr {max(1, $w / 16)}]} {
            lassign [$::photo get $x $y] r g b
            if {$r + $g + $b > 60} {
                incr n
            }
        }
    }
    return $n
}
# pixels: the photo's data, to compare frames.
proc pixels {} {
    return [$::photo data -format ppm]
}

set first [waitFor {$::pvr::gui::view::sent >= 1 && [idle] && [llength [::pvr::gui::stat::frames .stat.c]] >= 1} 30]
check "connect: the first frame arrives" $first "status: $::pvr::gui::statusText"
if {!$first} {
    finish
}
check "first frame: 128x128 in the photo" \
    {[image width $photo] == 128 && [image height $photo] == 128} "[image width $photo]x[image height $photo]"
set lit0 [lit]
check "first frame: the volume is visible (lit pixels)" {$lit0 > 5} "lit $lit0"
set frame0 [pixels]
# The server's report of the scene (docs/protocol.md, StatusReply).
set remote [dict get [$::pvr::gui::session list status] remote]
check "first frame: the view starts at the server's camera" \
    {$::pvr::gui::view::base ne {} && $::pvr::gui::view::azimuth == 0 &&
     $::pvr::gui::view::elevation == $::pvr::gui::view::baseElevation} "camera [dict filter $remote key camera_*]"
update
check "first frame: no time slider for a single volume" {![winfo ismapped .ctl.time]}
check "first frame: the editor spans the server's value range" \
    {[::pvr::gui::tfeditor::range .ctl.tf.editor] == [lmap v [dict get $remote value_range] {expr {double($v)}}]} \
    "range [::pvr::gui::tfeditor::range .ctl.tf.editor], value_range [dict get $remote value_range]"
# Issue 14, point 1: the editor draws the histogram the server counted (no
# file read by the client): its fractions are the server's counts over all
# voxels, and its bars are on the canvas.
set serverCounts [dict get [$::pvr::gui::session info] histogram]
set total 0
foreach n $serverCounts {incr total $n}
set editorHist $::pvr::gui::tfeditor::state(.ctl.tf.editor,hist)
check "editor: the histogram is the server's, 256 bins over its range" \
    {[llength [lindex $editorHist 1]] == 256 && $total == 32 * 32 * 32 && [lindex $serverCounts end] == 10 * 22 * 18 &&
     [lindex $editorHist 0 0] == 0.0 && [lindex $editorHist 0 end] == 200.0 &&
     abs([lindex $editorHist 1 0] - double([lindex $serverCounts 0]) / $total) < 1e-12 &&
     abs([lindex $editorHist 1 end] - double([lindex $serverCounts end]) / $total) < 1e-12} \
    "editor [lrange [lindex $editorHist 1] 0 3] server [lrange $serverCounts 0 3] total $total"
check "editor: the histogram's bars are drawn" {[llength [.ctl.tf.editor find withtag histogram]] >= 2} \
    "[llength [.ctl.tf.editor find withtag histogram]] bars"

# ---- Step 3: a drag on the image ----
# Each coarse frame as the GUI is told of it: its own size and reduction,
# the photo's size, and whether the photo holds it zoomed (every 4 x 4
# block of pixels of one colour, as `copy -zoom 4` makes it).
proc zoomedBlocks {zoom} {
    foreach {bx by} {0 0 16 16 15 17 8 24} {
        set want [$::photo get [expr {$bx * $zoom}] [expr {$by * $zoom}]]
        for {set y 0} {$y < $zoom} {incr y} {
            for {set x 0} {$x < $zoom} {incr x} {
                if {[$::photo get [expr {$bx * $zoom + $x}] [expr {$by * $zoom + $y}]] ne $want} {
                    return 0
                }
            }
        }
    }
    return 1
}
set ::coarseShown {}
trace add execution ::pvr::gui::onFrame enter {apply {{command op} {
    set timing [lindex $command 2]
    if {[dict get $timing quality] eq "coarse"} {
        lappend ::coarseShown [list [dict get $timing width]x[dict get $timing height]/[dict get $timing reduction] \
                                   [image width $::photo]x[image height $::photo] [zoomedBlocks 4]]
    }
}}}
set sentBefore $::pvr::gui::view::sent
set coarseBefore [expr {[info exists ::pvr::gui::coarseFrames] ? $::pvr::gui::coarseFrames : 0}]
set az0 $::pvr::gui::view::azimuth
set el0 $::pvr::gui::view::elevation
set img .view.image
event generate $img <ButtonPress-1> -x 40 -y 64 -button 1
for {set i 1} {$i <= 12} {incr i} {
    event generate $img <B1-Motion> -x [expr {40 + 5 * $i}] -y [expr {64 + $i}] -state 0x100
}
event generate $img <ButtonRelease-1> -x 100 -y 76 -button 1 -state 0x100
check "drag: the azimuth turned 30 degrees" \
    {abs(fmod($az0 - $::pvr::gui::view::azimuth + 360, 360) - 30) < 1e-6} "azimuth $::pvr::gui::view::azimuth"
check "drag: the elevation rose 6 degrees (dragging down)" {abs($::pvr::gui::view::elevation - $el0 - 6) < 1e-6} \
    "elevation $::pvr::gui::view::elevation from $el0"
waitFor {[idle]} 20
set requests [expr {$::pvr::gui::view::sent - $sentBefore}]
check "drag: 12 motion events coalesced into fewer requests" {$requests >= 1 && $requests < 12} "requests $requests"
set frame1 [pixels]
check "drag: the image changed" {$frame1 ne $frame0}
# Progressive refinement: the drag's requests were interactive renders,
# each showing a coarse frame first; the last view ends at full quality.
check "drag: coarse frames while dragging, the full-quality frame last" \
    {$::pvr::gui::coarseFrames > $coarseBefore && $::pvr::gui::lastQuality eq "full"} \
    "coarse [expr {$::pvr::gui::coarseFrames - $coarseBefore}], last $::pvr::gui::lastQuality"
check "drag: the volume is still visible" {[lit] > 5} "lit [lit]"
check "drag: coarse frames come at 32x32 and show zoomed to 128x128 in the photo" \
    {[llength $::coarseShown] > 0 && [lsort -unique $::coarseShown] eq {{32x32/4 128x128 1}}} \
    "[lsort -unique $::coarseShown]"

# ---- Step 4: the turn-right button ----
set sentBefore $::pvr::gui::view::sent
set az1 $::pvr::gui::view::azimuth
set button .ctl.view.right
event generate $button <Enter>
event generate $button <ButtonPress-1> -x 5 -y 5 -button 1
event generate $button <ButtonRelease-1> -x 5 -y 5 -button 1
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
check "button: the azimuth turned 15 degrees" \
    {abs(fmod($::pvr::gui::view::azimuth - $az1 + 360, 360) - 15) < 1e-6} "azimuth $::pvr::gui::view::azimuth"
set frame2 [pixels]
check "button: a new frame with other pixels" {$frame2 ne $frame1}

# ---- Step 5: the same view from a camera set explicitly ----
# The GUI's view is now the reported camera orbited: its eye raised by
# E - E0 towards the up vector and turned by the azimuth A about it,
# around the look-at point, the up vector kept (RenderRotation turns eye
# and up; the camera keeps the up's part across the view). A second
# session renders that camera, set explicitly, with the GUI's transfer
# function: the frames agree within 2/255 per channel.
proc turned {v axis degrees} {
    # Rodrigues: v turned by `degrees` about `axis` (right-handed).
    set a [expr {$degrees * acos(-1) / 180.0}]
    set k [::pvr::gui::view::normalize $axis]
    set kxv [::pvr::gui::view::cross $k $v]
    set kv [::pvr::gui::view::dot $k $v]
    return [lmap x $v c $kxv kk $k {expr {$x * cos($a) + $c * sin($a) + $kk * $kv * (1 - cos($a))}}]
}
set lookAt [dict get $remote camera_look_at]
set up [dict get $remote camera_up]
set toEye [::pvr::gui::view::addScaled [dict get $remote camera_eye] -1 $lookAt]
set raised [turned $toEye [::pvr::gui::view::cross $toEye $up] \
                [expr {$::pvr::gui::view::elevation - $::pvr::gui::view::baseElevation}]]
set eye [::pvr::gui::view::addScaled $lookAt 1 [turned $raised $up $::pvr::gui::view::azimuth]]
set refPhoto [image create photo]
pvr_session :ref
:ref image window $refPhoto
:ref open 127.0.0.1:$port -ranks 1
:ref set -dataset $::pvr::gui::opt(dataset) -imagesz 128,128 \
    -tf [::pvr::gui::tfeditor::points .ctl.tf.editor] \
    -eye [join $eye ,] -lookat [join $lookAt ,] -up [join $up ,] -fov [dict get $remote camera_fov_y_deg]
:ref render frame
:ref wait -timeout 20
set worst 0
for {set y 0} {$y < 128} {incr y} {
    for {set x 0} {$x < 128} {incr x} {
        foreach p [$photo get $x $y] q [$refPhoto get $x $y] {
            set worst [expr {max($worst, abs($p - $q))}]
        }
    }
}
rename :ref {}
check "button: the frame equals the reported camera turned, rendered by another session" {$worst <= 2} \
    "differs by $worst/255"

# ---- Step 5b: wheel zoom, middle-button pan, standard views ----
# Camera moves go to the server (`:s set -zoom/-pan/-view`), which applies
# them to the camera in force; the orbit on screen is committed first.
proc tanHalf {deg} { expr {tan($deg * acos(-1) / 360.0)} }
proc minus {a b} { lmap x $a y $b {expr {$x - $y}} }
set session $::pvr::gui::session
set camBefore [$session camera]
set litBefore [lit]
set sentBefore $::pvr::gui::view::sent
event generate $img <Button-4> -x 64 -y 64
event generate $img <Button-4> -x 64 -y 64
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
set camZoomed [$session camera]
check "wheel: two steps in zoom 1.25^2 on the server's camera" \
    {abs([tanHalf [dict get $camBefore fov_y_deg]] / [tanHalf [dict get $camZoomed fov_y_deg]] - 1.5625) < 1e-9} \
    "fov [dict get $camBefore fov_y_deg] -> [dict get $camZoomed fov_y_deg]"
check "wheel: the orbit on screen became the server's camera" \
    {[dict get $camZoomed automatic] == 0 && $::pvr::gui::view::azimuth == 0} "camera $camZoomed"
set litZoomed [lit]
check "wheel: the volume covers more pixels" {$litZoomed > $litBefore} "lit $litBefore -> $litZoomed"
set sentBefore $::pvr::gui::view::sent
event generate $img <MouseWheel> -delta -120 -x 64 -y 64
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
set camOut [$session camera]
check "mouse wheel delta < 0: zooms out by 1.25" \
    {abs([tanHalf [dict get $camOut fov_y_deg]] / [tanHalf [dict get $camZoomed fov_y_deg]] - 1.25) < 1e-9}
set framePanFrom [pixels]
set sentBefore $::pvr::gui::view::sent
event generate $img <ButtonPress-2> -x 64 -y 64 -button 2
for {set i 1} {$i <= 8} {incr i} {
    event generate $img <B2-Motion> -x [expr {64 + 4 * $i}] -y 64 -state 0x200
}
event generate $img <ButtonRelease-2> -x 96 -y 64 -button 2 -state 0x200
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
set camPanned [$session camera]
set eyeMoved [minus [dict get $camPanned eye] [dict get $camOut eye]]
set lookMoved [minus [dict get $camPanned look_at] [dict get $camOut look_at]]
check "middle drag: eye and look_at moved together" \
    {[::pvr::gui::view::dot $lookMoved $lookMoved] > 1e-6 && [pvrtest_near $eyeMoved $lookMoved]} \
    "eye by $eyeMoved, look_at by $lookMoved"
check "middle drag: a new frame" {[pixels] ne $framePanFrom}
# The image follows the pointer: dragged 20 pixels left (back towards the
# middle, so that nothing is cut off at the edge), the lit pixels' mean
# column moves 20 pixels left.
proc litCentreX {} {
    set sum 0.0
    set n 0
    for {set y 0} {$y < 128} {incr y 2} {
        for {set x 0} {$x < 128} {incr x 2} {
            lassign [$::photo get $x $y] r g b
            if {$r + $g + $b > 60} {
                set sum [expr {$sum + $x}]
                incr n
            }
        }
    }
    return [expr {$n ? $sum / $n : -1}]
}
set sentBefore $::pvr::gui::view::sent
set centreBefore [litCentreX]
event generate $img <ButtonPress-2> -x 60 -y 64 -button 2
event generate $img <B2-Motion> -x 40 -y 64 -state 0x200
event generate $img <ButtonRelease-2> -x 40 -y 64 -button 2 -state 0x200
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
set centreAfter [litCentreX]
check "middle drag left by 20 pixels: the volume moves left by about 20" \
    {abs($centreAfter - $centreBefore + 20) < 4} "centre x $centreBefore -> $centreAfter"
set sentBefore $::pvr::gui::view::sent
.ctl.view.std.v+z invoke
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
set camTop [$session camera]
set dir [minus [dict get $camTop look_at] [dict get $camTop eye]]
set dirLength [expr {sqrt([::pvr::gui::view::dot $dir $dir])}]
check "view button +z: looks along +z with up +y" \
    {abs([lindex $dir 2] / $dirLength - 1) < 1e-9 && [dict get $camTop up] eq {0 1 0}} "camera $camTop"
update
if {[auto_execok import] ne ""} {
    # The screen shows the frame: the lit pixels of the screenshot's image
    # area are those of the photo.
    set shot [file join $arg(-out) gui_camera_screenshot.png]
    exec import -window root $shot
    set shotPhoto [image create photo -file $shot]
    set x0 [winfo rootx $img]
    set y0 [winfo rooty $img]
    set worst 0
    for {set y 0} {$y < 128} {incr y 4} {
        for {set x 0} {$x < 128} {incr x 4} {
            foreach p [$photo get $x $y] q [$shotPhoto get [expr {$x0 + $x}] [expr {$y0 + $y}]] {
                set worst [expr {max($worst, abs($p - $q))}]
            }
        }
    }
    check "screenshot: the view on screen is the top view's frame" {$worst <= 2} "differs by $worst/255"
} else {
    puts "note: ImageMagick's import is not installed: no screenshot check"
}
set sentBefore $::pvr::gui::view::sent
.ctl.view.reset invoke
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
set camReset [$session camera]
check "Reset: the automatic camera again" {[dict get $camReset automatic] == 1} "camera $camReset"

# ---- Step 6: drag a transfer-function point ----
set editor .ctl.tf.editor
set sentBefore $::pvr::gui::view::sent
set points [::pvr::gui::tfeditor::normalized $editor]
lassign [::pvr::gui::tfeditor::toCanvas $editor [lindex $points end 0] [lindex $points end 4]] px py
set px [expr {int($px)}]
set py [expr {int($py)}]
event generate $editor <ButtonPress-1> -x $px -y $py -button 1
event generate $editor <B1-Motion> -x $px -y [expr {$py + 60}] -state 0x100
event generate $editor <ButtonRelease-1> -x $px -y [expr {$py + 60}] -button 1 -state 0x100
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
set opacity [lindex [::pvr::gui::tfeditor::normalized $editor] end 4]
check "tf: the last point's opacity went down" {$opacity < [lindex $points end 4]} "opacity $opacity"
check "tf: the change rendered a new frame" {$::pvr::gui::view::sent > $sentBefore && [pixels] ne $frame2}

# ---- Step 7: a ParaView preset through the GUI ----
set preset [file join $arg(-out) preset.json]
set f [open $preset w]
puts $f {[{"Name": "test", "RGBPoints": [0, 0, 0, 0, 120, 1, 0.5, 0, 200, 1, 1, 1],
          "Points": [0, 0, 0.5, 0, 100, 0.1, 0.5, 0, 200, 0.8, 0.5, 0]}]}
close $f
set sentBefore $::pvr::gui::view::sent
set frame3 [pixels]
set loaded [::pvr::gui::loadPreset $preset]
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
set serverPoints [dict get [$::pvr::gui::session list status] remote transfer_function]
set editorPoints [::pvr::gui::tfeditor::points $editor]
set same [expr {[llength $serverPoints] == [llength $editorPoints]}]
foreach a $serverPoints b $editorPoints {
    if {abs($a - $b) > 1e-6} { set same 0 }
}
check "preset: the editor holds the points the server read" {$loaded && $same && [llength $editorPoints] >= 15} \
    "editor $editorPoints, server $serverPoints"
check "preset: a frame renders with them" {$::pvr::gui::view::sent > $sentBefore && [pixels] ne $frame3}

# ---- Step 8: a rotation sequence ----
set ::pvr::gui::opt(axis) 0,0,1
set ::pvr::gui::opt(range) 0,5:12
set statFrames [llength [::pvr::gui::stat::frames .stat.c]]
.ctl.seq.go invoke
check "sequence: the GUI is busy while it runs" {$::pvr::gui::view::busy}
waitFor {[idle]} 30
check "sequence: the progress bar reached 6 of 6" \
    {$::pvr::gui::progress == 6 && [.bar.progress cget -maximum] == 6} "progress $::pvr::gui::progress"
check "sequence: six more bars in the performance graph" \
    {[llength [::pvr::gui::stat::frames .stat.c]] == min(60, $statFrames + 6)}
check "sequence: the status line reports it" {[string match "sequence done: 6 frames*" $::pvr::gui::statusText]} \
    $::pvr::gui::statusText
set timing [lindex [::pvr::gui::stat::frames .stat.c] end 1]
set phases 0
foreach k $::pvr::phases {
    incr phases [dict exists $timing $k]
}
check "graph: the frame's timing has every phase of ::pvr::phases" \
    {$phases == [llength $::pvr::phases] && $phases == 7} $timing

# ---- Step 9: the cluster and group window ----
::pvr::gui::layout::show $::pvr::gui::session
update
check "layout: the window shows the layout in force" \
    {[string match "*state open*render*" [.layout.report.t get 1.0 end]]} [.layout.report.t get 1.0 end]
.layout.report.b.mem invoke
check "layout: memory per cluster from the server" \
    {[string match "performance memory cluster:*" [.layout.report.t get 1.0 end]]} [.layout.report.t get 1.0 end]
set sentBefore $::pvr::gui::view::sent
.layout.buttons.apply invoke
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
check "layout: apply sets the clusters and renders" \
    {[string match "frame * in * ms*" $::pvr::gui::statusText]} $::pvr::gui::statusText

set box .layout.comp.sc
set offered [$box cget -values]
set strategies [dict get [$::pvr::gui::session list status] remote strategies]
check "strategy box: offers exactly the server's strategies" {[llength $offered] > 0 && $offered eq $strategies} \
    "box {$offered}, server {$strategies}"
foreach name [lreverse $offered] {
    set sentBefore $::pvr::gui::view::sent
    $box set $name
    event generate $box <<ComboboxSelected>>
    .layout.buttons.apply invoke
    waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
    set inForce [dict get [$::pvr::gui::session list status] remote strategy]
    check "strategy box: $name is in force and renders a frame, no error on the status line" \
        {$inForce eq $name && [string match "frame * in * ms*" $::pvr::gui::statusText] && $::pvr::gui::errors == 0} \
        "in force $inForce; status: $::pvr::gui::statusText"
}

# ---- Step 10: the time slider of a series ----
set sentBefore $::pvr::gui::view::sent
::pvr::gui::loadDataset blockseries/blockseries.series.json
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
update
check "time: the slider shows for a series, over its 3 steps" \
    {[winfo ismapped .ctl.time] && [.ctl.time.scale cget -to] == 2 && $::pvr::gui::timestep == 0} \
    "mapped [winfo ismapped .ctl.time], to [.ctl.time.scale cget -to], step $::pvr::gui::timestep"
set frameStep0 [pixels]
set sentBefore $::pvr::gui::view::sent
.ctl.time.scale set 2
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
set remoteStep [dict get [$::pvr::gui::session list status] remote timestep]
check "time: moving the slider sets step 2 and renders another frame" \
    {$remoteStep == 2 && [pixels] ne $frameStep0 && $::pvr::gui::errors == 0} \
    "server step $remoteStep; status: $::pvr::gui::statusText"

# ---- Step 10b: issue 14, point 9 ----
# A 1024x1024 frame in an 800x600 window: the view shows it scaled inside
# the window; the screenshot's pixels there are the shown image's.
wm geometry . 800x600
set sentBefore $::pvr::gui::view::sent
set ::pvr::gui::opt(imagesz) 1024x1024
::pvr::gui::applyImageSize
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 30
update
set shownImage [.view.image cget -image]
set lx [winfo rootx .view.image]
set ly [winfo rooty .view.image]
set sw [image width $shownImage]
set sh [image height $shownImage]
check "fit: a 1024x1024 frame arrives whole in the photo" {[image width $photo] == 1024 && [image height $photo] == 1024}
check "fit: the shown image lies inside the 800x600 window" \
    {[winfo width .] <= 800 && [winfo height .] <= 600 && $sw < 1024 && $lx >= [winfo rootx .] &&
     $ly >= [winfo rooty .] && $lx + $sw <= [winfo rootx .] + [winfo width .] &&
     $ly + $sh <= [winfo rooty .] + [winfo height .] && [winfo width .view.image] == $sw} \
    "window [winfo width .]x[winfo height .], image ${sw}x$sh at $lx,$ly"
if {[auto_execok import] ne ""} {
    set shotFile [file join $arg(-out) gui_fit_screenshot.png]
    exec import -window root $shotFile
    set shot [image create photo -file $shotFile]
    # Every 8th pixel of the shown image, on the screen where the label is.
    set same 0
    set total 0
    set lit 0
    for {set y 0} {$y < $sh} {incr y 8} {
        for {set x 0} {$x < $sw} {incr x 8} {
            incr total
            set want [$shownImage get $x $y]
            set got [$shot get [expr {$lx + $x}] [expr {$ly + $y}]]
            if {[::tcl::mathfunc::max {*}[lmap a $want b $got {expr {abs($a - $b)}}]] <= 2} {
                incr same
            }
            if {[::tcl::mathop::+ {*}$want] > 60} {
                incr lit
            }
        }
    }
    check "fit: the screenshot shows the scaled frame where the view is" {$same == $total && $lit > 0} \
        "$same of $total pixels agree, $lit lit"
    image delete $shot
}
wm geometry . {}
set ::pvr::gui::opt(imagesz) 128x128
set sentBefore $::pvr::gui::view::sent
::pvr::gui::applyImageSize
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 30

# The preset library in the Presets menu, and one of it renders.
set menu .ctl.render.presets.m
set labels {}
for {set i 0} {$i <= [$menu index end]} {incr i} {
    lappend labels [expr {[$menu type $i] eq "command" ? [$menu entrycget $i -label] : "-"}]
}
set missing {}
foreach name {{ct bone} {ct skin} {ct muscle} {grey ramp} {cool to warm} viridis {black body}} {
    if {$name ni $labels} {
        lappend missing $name
    }
}
check "presets: the menu lists the shipped library" {$missing eq {}} "missing $missing; menu $labels"
set sentBefore $::pvr::gui::view::sent
set before [pixels]
$menu invoke [lsearch -exact $labels {cool to warm}]
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
check "presets: cool to warm renders a new frame" {[pixels] ne $before && $::pvr::gui::errors == 0} \
    $::pvr::gui::statusText

# Background, shading and step.
set sentBefore $::pvr::gui::view::sent
::pvr::gui::render::applyBackground #0000ff
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
check "background: the frame's corner is the chosen blue" {[$photo get 0 0] eq {0 0 255}} [$photo get 0 0]
set sentBefore $::pvr::gui::view::sent
set before [pixels]
.ctl.render.shading invoke
waitFor {$::pvr::gui::view::sent > $sentBefore && [idle]} 20
check "shading: the checkbox turns it off and renders another frame" \
    {[$::pvr::gui::session set -shading] eq "off" && [pixels] ne $before} [$::pvr::gui::session set -shading]
set ::pvr::gui::render::step 0.25
::pvr::gui::render::applyStep
waitFor {[idle]} 20
check "step: the entry sets -step" {[$::pvr::gui::session set -step] eq "0.25"} [$::pvr::gui::session set -step]

# Save image: a PNG equal to the frame on screen.
set saved [file join $arg(-out) saved_frame.png]
file delete $saved
::pvr::gui::render::saveImage $saved
waitFor {[idle] && $::pvr::gui::render::saving eq ""} 20
set worst 256
if {[file exists $saved]} {
    set read [image create photo -file $saved]
    set worst [expr {[image width $read] == [image width $photo] ? 0 : 256}]
    for {set y 0} {$y < [image height $photo] && $worst < 256} {incr y} {
        for {set x 0} {$x < [image width $photo]} {incr x} {
            foreach p [$photo get $x $y] q [$read get $x $y] {
                set worst [expr {max($worst, abs($p - $q))}]
            }
        }
    }
    image delete $read
}
check "save image: writes a PNG equal to the frame" {$worst == 0 && [glob -nocomplain [file join $arg(-out) .pvr-save-*]] eq {}} \
    "differs by $worst; status: $::pvr::gui::statusText"

# Save animation: the rotation sequence as a GIF (pvrsh runs ffmpeg).
if {[auto_execok ffmpeg] ne ""} {
    set movie [file join $arg(-out) saved_movie.gif]
    file delete $movie
    set ::pvr::gui::opt(range) 0,3:12
    ::pvr::gui::render::saveAnimation $movie
    waitFor {[idle] && $::pvr::gui::render::saving eq ""} 30
    check "save animation: writes the sequence as a GIF" \
        {[file exists $movie] && [file size $movie] > 100 && [string match "saved saved_movie.gif*" $::pvr::gui::statusText]} \
        $::pvr::gui::statusText
}

# Performance answers in human units: no long fractions.
::pvr::gui::layout::show $::pvr::gui::session
.layout.report.b.mem invoke
set memoryText [.layout.report.t get 1.0 end]
.layout.report.b.lat invoke
set latencyText [.layout.report.t get 1.0 end]
check "performance: memory in KB or MB, latency in ms, no long fractions" \
    {[regexp {[0-9.]+ (KB|MB|GB)} $memoryText] && [regexp {[0-9.]+ ms} $latencyText] &&
     ![regexp {\.[0-9]{5,}} $memoryText$latencyText]} "$memoryText\n$latencyText"
check "performance: human units of bytes and seconds" \
    {[::pvr::gui::layout::human bytes 1572864] eq "1.5 MB" && [::pvr::gui::layout::human model_seconds 0.0123456789] eq "12.35 ms"}

# ---- Step 11: artifacts ----
$photo write [file join $arg(-out) gui_frame.png] -format png
check "artifact: gui_frame.png written" {[file size [file join $arg(-out) gui_frame.png]] > 100}
update
if {[auto_execok import] ne ""} {
    set shot [file join $arg(-out) gui_screenshot.png]
    if {[catch {exec import -window root $shot} message]} {
        puts "note: import failed: $message"
    } else {
        check "artifact: gui_screenshot.png written" {[file size $shot] > 1000}
    }
}
    }
}
if {[catch steps message]} {
    check "no Tcl error" 0 "$message\n$::errorInfo"
}
check "no errors on the status line" {$::pvr::gui::errors == 0} "$::pvr::gui::errors errors"

# ---- Step 12: a job that dies (issue 14, point 9) ----
# The session's pvr-node is killed (a descendant of the pvrd this test
# started, found by parent ids): the button offers Connect again, and
# Render says so instead of pvrsh's Tcl advice.
proc descendants {pid} {
    set found {}
    foreach child [split [string trim [exec sh -c "pgrep -P $pid || true"]] \n] {
        if {$child ne ""} {
            lappend found $child {*}[descendants $child]
        }
    }
    return $found
}
if {[catch {
    set nodes {}
    foreach p [descendants [lindex [pid $pvrdChan] 0]] {
        if {[catch {exec cat /proc/$p/comm} name] == 0 && [string match pvr-node* $name]} {
            lappend nodes $p
        }
    }
    check "dead job: the session's pvr-node is found" {[llength $nodes] > 0}
    foreach p $nodes {
        exec kill -KILL $p
    }
    set gone [waitFor {[.ctl.conn.open cget -text] eq "Connect"} 30]
    check "dead job: the button says Connect again" {$gone} \
        "button [.ctl.conn.open cget -text]; status: $::pvr::gui::statusText"
    .ctl.view.render invoke
    check "dead job: Render says to connect, without Tcl advice" \
        {[string match "*press Connect*" $::pvr::gui::statusText] && ![string match "*use:*" $::pvr::gui::statusText]} \
        $::pvr::gui::statusText
} message]} {
    check "dead job: no Tcl error" 0 "$message\n$::errorInfo"
}
puts "artifacts in $arg(-out)"
finish
