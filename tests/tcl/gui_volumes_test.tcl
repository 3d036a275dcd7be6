# gui_volumes_test.tcl -- the GUI's volume panel (tcl/gui_volumes.tcl),
# issue 12, against the scripted stand-in server of tests/pvrsh/fake_pvrd.tcl,
# which records the SetScene payloads the GUI's session sends.
#
#   xvfb-run -a pvrsh gui_volumes_test.tcl -source SRC -out DIR
#
# Checks, by the bytes sent and the widgets:
#   1. with one dataset the panel is hidden and the editor sends `set -tf`;
#   2. "Add volume" adds a catalog dataset: the whole list goes out (the
#      dataset shown so far as the volume "volume"), the panel shows both
#      with a visibility checkbutton each, and the new one is edited;
#   3. unticking a volume sends it with "visible": false and renders;
#   4. the editor's points go to the volume chosen with its radiobutton;
#   5. choosing a dataset in the box is one volume again: the panel hides.
# Writes DIR/gui_volumes_screenshot.png (ImageMagick's import) with the
# panel shown. Exits 0 when all pass, 1 otherwise.

package require Tk

array set arg {-source "" -out .}
foreach {k v} $argv {
    set arg($k) $v
}
if {$arg(-source) eq ""} {
    puts stderr "usage: gui_volumes_test.tcl -source SRC -out DIR"
    exit 2
}
file mkdir $arg(-out)
source [file join [file dirname [info script]] gui_harness.tcl]

proc finish {} {
    catch {$::pvr::gui::session close}
    catch {::fakepvrd::stop}
    puts [expr {$::failures == 0 ? "gui volumes test passed" : "gui volumes test: $::failures failures"}]
    exit [expr {$::failures == 0 ? 0 : 1}]
}

after 60000 {
    puts "FAIL timeout: the test did not finish in 60 s"
    incr ::failures
    finish
}

source [file join $arg(-source) tests pvrsh fake_pvrd.tcl]
# A catalog of two datasets: u32 count, then per entry (docs/protocol.md,
# CatalogEntry) str name, u32 steps, str file, str format, u32[3] dims,
# str dtype, str note.
proc ::fakepvrd::catalog {} {
    set out [binary format i 2]
    foreach name {ball cube} {
        append out [str $name] [binary format i 1] [str $name/$name.json] [str raw+json] \
            [binary format iii 32 32 32] [str uint8] [str ""]
    }
    return $out
}
# The scene JSON of the SetScenes received, in order.
proc scenes {} {
    set out {}
    foreach r $::fakepvrd::received {
        if {[lindex $r 0] eq "18"} { lappend out [lindex $r 2] }
    }
    return $out
}
# 1 when the number lists A and B agree element by element.
proc same {a b} {
    if {[llength $a] != [llength $b]} { return 0 }
    foreach x $a y $b {
        if {abs($x - $y) > 1e-9} { return 0 }
    }
    return 1
}
proc idle {} {
    expr {!$::pvr::gui::view::busy && !$::pvr::gui::view::dirty}
}
# Waits until a SetScene beyond the first `n` arrived and the GUI is idle.
proc sentAfter {n} {
    waitFor "\[llength \[scenes\]\] > $n && \[idle\]" 10
}

set port [::fakepvrd::start ready]

proc steps {} {
    uplevel #0 {
source [file join $arg(-source) tcl gui.tcl]
::pvr::gui::main -host 127.0.0.1:$port -ranks 1 -dataset ball -imagesz 64x64
set first [waitFor {$::pvr::gui::view::sent >= 1 && [idle]} 20]
check "connect: the first frame" $first $::pvr::gui::statusText
update
set editor .ctl.tf.editor

# ---- 1: one dataset ----
check "one dataset: no volume panel" {![winfo ismapped .ctl.vols]}
set n [llength [scenes]]
::pvr::gui::tfeditor::points $editor {0 0 0 0 0 0.5 1 1 1 0.5 1 1 1 1 1}
sentAfter $n
check "one dataset: the editor sends set -tf (a top-level transfer function)" \
    {[string match {*"transfer_function":\{"absolute":null,"paraview":null,"paraview_preset":null,"points":*} [lindex [scenes] end 1]]} \
    [lindex [scenes] end]

# ---- 2: add a volume ----
set menu .ctl.data.addvol.m
set labels [lmap i [lsearch -all [lrepeat [expr {[$menu index end] + 1}] x] x] {$menu entrycget $i -label}]
check "add menu: the catalog's datasets" {$labels eq {ball cube}} $labels
set n [llength [scenes]]
$menu invoke 1
sentAfter $n
update
set sent [lindex [scenes] $n]
check "add: the whole list goes out, the dataset shown so far as volume \"volume\"" \
    {[lindex $sent 0] eq "" && [string match {{"transfer_function":null,"volumes":\[{"dataset":"ball","name":"volume","transfer_function":{"points":*},"visible":true},{"dataset":"cube","name":"cube","visible":true}\]}} [lindex $sent 1]]} \
    $sent
check "add: the panel shows both volumes" \
    {[winfo ismapped .ctl.vols] && [.ctl.vols.rows.v0 cget -text] eq "volume" && [.ctl.vols.rows.v1 cget -text] eq "cube"}
check "add: the new volume is the one edited" {$::pvr::gui::volumes::selected eq "cube"}
check "add: the new volume takes the editor's points, as shown" \
    {[string match {*"name":"cube","transfer_function":\{"points":\[\[0.0,0.0,0.0,0.0,0.0\],\[0.5,1.0,1.0,1.0,0.5\],*} [lindex [scenes] end 1]]} \
    [lindex [scenes] end]
check "add: a frame rendered after it" {[idle] && $::pvr::gui::errors == 0} $::pvr::gui::statusText

# ---- 3: visibility ----
set n [llength [scenes]]
set sentFrames $::pvr::gui::view::sent
.ctl.vols.rows.v0 invoke
sentAfter $n
check "untick: the volume goes out invisible" \
    {[string match {*"name":"volume",*"visible":false\},\{"dataset":"cube"*"visible":true\}\]\}} [lindex [scenes] end 1]]} \
    [lindex [scenes] end]
check "untick: a frame rendered" {$::pvr::gui::view::sent > $sentFrames}
check "untick: volume list says so" {[dict get [$::pvr::gui::session volume configure volume] visible] == 0}

# ---- 4: the editor edits the chosen volume ----
set n [llength [scenes]]
::pvr::gui::tfeditor::points $editor {0 1 0 0 0 1 1 0 0 0.8}
sentAfter $n
check "editor: the points go to volume cube" \
    {[string match {*"name":"cube","transfer_function":\{"points":\[\[0.0,1.0,0.0,0.0,0.0\],\[1.0,1.0,0.0,0.0,0.8\]\]\}*} [lindex [scenes] end 1]]} \
    [lindex [scenes] end]
.ctl.vols.rows.e0 invoke
update
check "radiobutton: volume \"volume\" is edited, its points in the editor" \
    {$::pvr::gui::volumes::selected eq "volume" && [same [::pvr::gui::tfeditor::points $editor] {0 0 0 0 0 0.5 1 1 1 0.5 1 1 1 1 1}]} \
    [::pvr::gui::tfeditor::points $editor]
set n [llength [scenes]]
::pvr::gui::tfeditor::points $editor {0 0 0 1 0 1 0 0 1 0.3}
sentAfter $n
check "editor: now the points go to volume \"volume\", cube keeps its own" \
    {[string match {*"name":"volume","transfer_function":\{"points":\[\[0.0,0.0,0.0,1.0,0.0\],*"name":"cube","transfer_function":\{"points":\[\[0.0,1.0,*} [lindex [scenes] end 1]]} \
    [lindex [scenes] end]
update
check "panel: each row describes its volume's transfer function" \
    {[.ctl.vols.rows.d0 cget -text] eq "ball (2 points 0..1)" && [.ctl.vols.rows.d1 cget -text] eq "cube (2 points 0..1)"} \
    "[.ctl.vols.rows.d0 cget -text] / [.ctl.vols.rows.d1 cget -text]"
if {[auto_execok import] ne ""} {
    set shot [file join $arg(-out) gui_volumes_screenshot.png]
    exec import -window root $shot
    check "screenshot written" {[file size $shot] > 1000}
}

# ---- 5: a dataset from the box: one volume again ----
set n [llength [scenes]]
::pvr::gui::loadDataset ball
sentAfter $n
update
# The dataset (the list goes), then the editor's points as set -tf.
set byBox [lrange [scenes] $n end]
check "dataset box: exactly one volume again, the panel hidden" \
    {[lindex $byBox 0 0] eq "ball" && [string match {*"volumes":null*} [lindex $byBox 0 1]] && ![winfo ismapped .ctl.vols] &&
     [llength [$::pvr::gui::session volume list]] == 1} $byBox
check "dataset box: the editor sends set -tf again" \
    {[string match {\{"transfer_function":\{"absolute":null,*"points":*} [lindex $byBox end 1]]} $byBox
check "no errors on the status line" {$::pvr::gui::errors == 0} $::pvr::gui::statusText
    }
}
if {[catch steps message]} {
    check "no Tcl error" 0 "$message\n$::errorInfo"
}
finish
