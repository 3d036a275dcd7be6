# gui.tcl -- the PVR GUI after Figure 13 of paper 003, started by
# `pvrsh examples/gui.tcl ?-host HOST:PORT? ?-ranks N? ?-dataset NAME?
# ?-imagesz WxH?`.
#
# Windows:
#   .       image view (drag to rotate; scaled to the window, gui_fit.tcl),
#           connection, dataset, image size, view buttons, rotation
#           sequences, rendering controls, presets and saving
#           (gui_render.tcl), transfer-function editor,
#           a time slider for a series dataset, the scene's volumes with
#           their visibility and the one the editor edits (gui_volumes.tcl),
#           progress bar and status line
#   .stat   per-frame times, one bar part per phase of ::pvr::phases (stat.tcl)
#   .layout cluster and group configuration (gui_layout.tcl)
#
# One session, :pvrgui. Frames go into the photo ::pvr::gui::image through
# `:s image window`; `:s image callback` reports each frame's timing, and
# `:s notify` (done, cancelled, error) ends a request. Every request goes
# through ::pvr::gui::view, which keeps at most one in flight.
#
# What the server says about the scene comes from `list status` (docs/
# protocol.md, StatusReply): the camera the view orbits, the data's value
# range and 256-bin histogram for the transfer-function editor (counted by
# the server when it loaded the data: no file is read here), the points of
# a loaded preset, and the compositing strategies the layout window offers.

package require Tk 8.6

namespace eval ::pvr::gui {
    variable dir [file dirname [file normalize [info script]]]
    # The session object command and the photo frames go into.
    variable session :pvrgui
    variable image ::pvr::gui::image
    # Connection and scene settings, bound to widgets.
    variable opt
    array set opt {
        host 127.0.0.1:7350
        ranks 1
        dataset ""
        imagesz 512x512
        tflo 0
        tfhi 1
        axis 0,0,1
        range 0,35:36
    }
    # Status line text and its kind (info, busy, error); progress bar value.
    variable statusText "not connected"
    variable progress 0
    # The request in flight: kind (frame or sequence), frames done, total,
    # and its start in microseconds.
    variable request [dict create kind none done 0 total 0 start 0]
    # Request-to-pixels latency of the last single frame, seconds.
    variable lastLatency 0
    # A transfer-function change waits here until the request in flight ends.
    variable tfPending 0
    # A new dataset: the editor takes the server's value range before the
    # next request.
    variable rangePending 0
    # Whether the session is open (kept here: `list status` asks the server).
    variable connected 0
    # Errors shown on the status line so far.
    variable errors 0
    # Time series: the slider's position (a double while dragging) and the
    # step the session shows.
    variable timeValue 0
    variable timestep 0
}

foreach file {stat.tcl tfeditor.tcl gui_view.tcl gui_layout.tcl gui_fit.tcl gui_render.tcl gui_volumes.tcl} {
    source [file join $::pvr::gui::dir $file]
}
unset file

# ::pvr::gui::main --
#   Builds the windows, and connects when -host was given.
# Arguments: option value pairs (see the file header).
proc ::pvr::gui::main {args} {
    variable opt
    variable session
    if {[llength $args] % 2 != 0} {
        return -code error -errorcode {PVR ARGS} \
            "usage: gui.tcl ?-host HOST:PORT? ?-ranks N? ?-dataset NAME? ?-imagesz WxH?"
    }
    set connect 0
    foreach {key value} $args {
        set name [string range $key 1 end]
        if {$name ni {host ranks dataset imagesz}} {
            return -code error -errorcode {PVR ARGS OPTION} \
                "bad option \"$key\": must be -host, -ranks, -dataset or -imagesz"
        }
        set opt($name) $value
        if {$name eq "host"} {
            set connect 1
        }
    }
    if {[info exists ::env(PVR_SERVER)] && !$connect} {
        set opt(host) $::env(PVR_SERVER)
    }
    # The GUI shows progress itself; no per-frame lines on stderr.
    set ::pvr::progress 0
    interp bgerror {} ::pvr::gui::backgroundError
    buildMain
    buildStat
    if {[info commands $session] eq ""} {
        pvr_session $session
    }
    $session image window $::pvr::gui::image
    $session image callback ::pvr::gui::onFrame
    $session notify ::pvr::gui::onNotify
    ::pvr::gui::view::attach .view.image [list ::pvr::gui::send] ::pvr::gui::readScene [list $session set]
    if {$connect} {
        after idle ::pvr::gui::connect
    }
}

# ---- Windows ----

proc ::pvr::gui::buildMain {} {
    variable image
    variable opt
    wm title . "PVR"
    lassign [split $opt(imagesz) x] width height
    image create photo $image -width $width -height $height
    $image put #202020 -to 0 0 $width $height

    # Left: the image view. Right: the controls.
    ttk::frame .view -padding 4
    label .view.image -image $image -background black -borderwidth 0 -cursor fleur
    ttk::frame .ctl -padding 4

    # Connection.
    set f [ttk::labelframe .ctl.conn -text "Server" -padding 4]
    ttk::entry $f.host -width 20 -textvariable ::pvr::gui::opt(host)
    ttk::label $f.rl -text "ranks"
    ttk::spinbox $f.ranks -from 1 -to 256 -width 4 -textvariable ::pvr::gui::opt(ranks)
    ttk::button $f.open -text "Connect" -command ::pvr::gui::toggleConnection
    pack $f.host $f.rl $f.ranks $f.open -side left -padx 2

    # Dataset and image size.
    set f [ttk::labelframe .ctl.data -text "Dataset and image" -padding 4]
    ttk::combobox $f.dataset -width 34 -state readonly -textvariable ::pvr::gui::opt(dataset)
    bind $f.dataset <<ComboboxSelected>> {::pvr::gui::loadDataset $::pvr::gui::opt(dataset)}
    ttk::label $f.sl -text "image size"
    ttk::combobox $f.size -width 10 -textvariable ::pvr::gui::opt(imagesz) \
        -values {256x256 384x384 512x512 640x480 768x768 1024x1024}
    bind $f.size <<ComboboxSelected>> ::pvr::gui::applyImageSize
    bind $f.size <Return> ::pvr::gui::applyImageSize
    ::pvr::gui::volumes::addButton $f.addvol
    grid $f.dataset - - -sticky we -pady 2
    grid $f.sl $f.size $f.addvol -sticky w -pady 2 -padx 2

    # The scene's volumes: shown once a volume is added (gui_volumes.tcl).
    ::pvr::gui::volumes::build .ctl.vols

    # Time series: a slider over the steps, shown only for a dataset with
    # more than one (showTimeSteps).
    set f [ttk::labelframe .ctl.time -text "Time step" -padding 4]
    ttk::scale $f.scale -from 0 -to 1 -length 240 -variable ::pvr::gui::timeValue \
        -command ::pvr::gui::timeStepMoved
    ttk::label $f.step -width 12 -textvariable ::pvr::gui::timestep
    pack $f.scale $f.step -side left -padx 2

    # View: buttons turn by 15 degrees; the image turns by dragging.
    set f [ttk::labelframe .ctl.view -text "View (drag: rotate, wheel: zoom, middle drag: pan)" -padding 4]
    ttk::button $f.left -text "\u25c0" -width 3 -command {::pvr::gui::view::turn -15 0}
    ttk::button $f.right -text "\u25b6" -width 3 -command {::pvr::gui::view::turn 15 0}
    ttk::button $f.up -text "\u25b2" -width 3 -command {::pvr::gui::view::turn 0 15}
    ttk::button $f.down -text "\u25bc" -width 3 -command {::pvr::gui::view::turn 0 -15}
    ttk::button $f.reset -text "Reset" -command ::pvr::gui::view::reset
    ttk::button $f.render -text "Render" -command ::pvr::gui::requestFrame
    ttk::label $f.angles -width 30 -textvariable ::pvr::gui::anglesText
    grid x $f.up x $f.reset -padx 1 -pady 1
    grid $f.left $f.render $f.right $f.angles -padx 1 -pady 1
    grid x $f.down x -padx 1 -pady 1
    # Standard views (camera moves on the server, gui_view.tcl).
    ttk::frame $f.std
    foreach name {+x -x +y -y +z -z iso} {
        ttk::button $f.std.v$name -text $name -width 3 -command [list ::pvr::gui::view::move -view $name]
        pack $f.std.v$name -side left -padx 1
    }
    grid $f.std - - - -pady 2 -sticky w
    trace add variable ::pvr::gui::view::azimuth write ::pvr::gui::showAngles
    trace add variable ::pvr::gui::view::elevation write ::pvr::gui::showAngles
    showAngles

    # Rotation sequences, Table 1: render rotate X,Y,Z S,E:N.
    set f [ttk::labelframe .ctl.seq -text "Rotation sequence" -padding 4]
    ttk::label $f.al -text "axis"
    ttk::entry $f.axis -width 8 -textvariable ::pvr::gui::opt(axis)
    ttk::label $f.rl -text "S,E:N"
    ttk::entry $f.range -width 9 -textvariable ::pvr::gui::opt(range)
    ttk::button $f.go -text "Render" -command ::pvr::gui::renderSequence
    ttk::button $f.cancel -text "Cancel" -command ::pvr::gui::cancel
    pack $f.al $f.axis $f.rl $f.range $f.go $f.cancel -side left -padx 2

    # Transfer function: the editor and its scalar range.
    set f [ttk::labelframe .ctl.tf -text "Transfer function (drag, click to add, right-click to remove)" -padding 4]
    ::pvr::gui::tfeditor::create $f.editor -command ::pvr::gui::tfChanged -width 380 -height 150
    ttk::frame $f.range
    ttk::label $f.range.l -text "scalar range"
    ttk::entry $f.range.lo -width 9 -textvariable ::pvr::gui::opt(tflo)
    ttk::entry $f.range.hi -width 9 -textvariable ::pvr::gui::opt(tfhi)
    ttk::button $f.range.set -text "Set" -command ::pvr::gui::applyTfRange
    ttk::button $f.range.preset -text "Preset\u2026" -command ::pvr::gui::choosePreset
    pack $f.range.l $f.range.lo $f.range.hi $f.range.set $f.range.preset -side left -padx 2
    pack $f.editor -fill both -expand 1
    pack $f.range -anchor w -pady 2

    # Other windows.
    set f [ttk::frame .ctl.more]
    ttk::button $f.layout -text "Clusters and groups\u2026" -command {::pvr::gui::layout::show $::pvr::gui::session}
    ttk::button $f.stat -text "Performance graph\u2026" -command {wm deiconify .stat; raise .stat}
    pack $f.layout $f.stat -side left -padx 2

    ::pvr::gui::render::build .ctl.render

    pack .ctl.conn .ctl.data .ctl.view .ctl.seq .ctl.render .ctl.tf .ctl.more -fill x -pady 3

    # Bottom: progress bar and status line.
    ttk::frame .bar -padding {4 2}
    ttk::progressbar .bar.progress -length 160 -mode determinate -variable ::pvr::gui::progress
    ttk::label .bar.status -textvariable ::pvr::gui::statusText -anchor w
    pack .bar.progress -side left
    pack .bar.status -side left -fill x -expand 1 -padx 6

    # The view takes what the window has beside the controls.
    grid .view .ctl -sticky nsew
    grid .bar - -sticky we
    grid columnconfigure . 0 -weight 1
    grid rowconfigure . 0 -weight 1
    ::pvr::gui::fit::attach
}

proc ::pvr::gui::buildStat {} {
    toplevel .stat
    wm title .stat "PVR frame times"
    canvas .stat.c -width 600 -height 200
    pack .stat.c -fill both -expand 1
    ::pvr::gui::stat::attach .stat.c
    wm protocol .stat WM_DELETE_WINDOW {wm withdraw .stat}
    # Below the main window (a window manager may place it elsewhere).
    update idletasks
    wm geometry .stat +[winfo rootx .]+[expr {[winfo rooty .] + [winfo reqheight .] + 40}]
}

proc ::pvr::gui::showAngles {args} {
    set ::pvr::gui::anglesText [format "azimuth %5.1f\u00b0 elevation %5.1f\u00b0" \
                                    $::pvr::gui::view::azimuth $::pvr::gui::view::elevation]
}

# ::pvr::gui::status --
#   Sets the status line; kind is info, busy or error (red).
proc ::pvr::gui::status {text {kind info}} {
    variable statusText
    set statusText $text
    if {[winfo exists .bar.status]} {
        .bar.status configure -foreground [expr {$kind eq "error" ? "#b00000" : "black"}]
    }
    if {$kind eq "error"} {
        incr ::pvr::gui::errors
        puts stderr "pvr gui: $text"
    }
}

proc ::pvr::gui::backgroundError {message options} {
    status $message error
}

# ---- Connection and dataset ----

proc ::pvr::gui::toggleConnection {} {
    variable connected
    if {$connected} {
        disconnect
    } else {
        connect
    }
}

proc ::pvr::gui::markConnected {on} {
    variable connected
    set connected $on
    if {[winfo exists .ctl.conn.open]} {
        .ctl.conn.open configure -text [expr {$on ? "Disconnect" : "Connect"}]
    }
}

# ::pvr::gui::connect --
#   Opens the session, lists the catalog, and loads -dataset (or the first
#   dataset). Results: 1 when connected.
proc ::pvr::gui::connect {} {
    variable session
    variable opt
    status "connecting to $opt(host) with $opt(ranks) ranks\u2026" busy
    .ctl.conn.open configure -state disabled
    set failed [catch {$session open $opt(host) -ranks $opt(ranks)} message]
    .ctl.conn.open configure -state normal
    if {$failed} {
        status "cannot connect: $message" error
        return 0
    }
    markConnected 1
    set datasets {}
    if {[catch {$session list datasets} datasets]} {
        status "connected; no catalog: $datasets" error
        set datasets {}
    }
    .ctl.data.dataset configure -values $datasets
    ::pvr::gui::volumes::setDatasets $datasets
    set name $opt(dataset)
    if {$name ne "" && $name ni $datasets} {
        # A directory name stands for the sidecar inside it.
        set match [lsearch -inline -glob $datasets $name/*]
        set name [expr {$match ne "" ? $match : $name}]
    }
    if {$name eq "" && [llength $datasets] > 0} {
        set name [lindex $datasets 0]
    }
    status "connected to $opt(host): [llength $datasets] datasets"
    if {$name ne ""} {
        loadDataset $name
    }
    return 1
}

# ::pvr::gui::checkConnection --
#   After an asynchronous error: when the session is no longer open (the
#   job died, the server closed it), the button offers Connect again.
proc ::pvr::gui::checkConnection {} {
    variable session
    variable connected
    if {!$connected} {
        return
    }
    set state failed
    catch {set state [dict get [$session list status] state]}
    if {$state ne "open"} {
        markConnected 0
        ::pvr::gui::view::finished all
        status "the session ended (state $state): press Connect to start a new one" error
    }
}

proc ::pvr::gui::disconnect {} {
    variable session
    catch {$session close}
    markConnected 0
    ::pvr::gui::view::finished all
    status "disconnected"
}

# ::pvr::gui::serverHistogram --
#   The server's histogram of the data (status `histogram`, 256 counts over
#   `value_range`) as the editor takes it: a dict with edges (257 scalars)
#   and fractions of all voxels; empty when the status has none.
proc ::pvr::gui::serverHistogram {remote} {
    if {![dict exists $remote histogram] || ![dict exists $remote value_range]} {
        return {}
    }
    set counts [dict get $remote histogram]
    lassign [dict get $remote value_range] lo hi
    set total 0
    foreach n $counts {
        incr total $n
    }
    if {[llength $counts] == 0 || $total == 0 || !($lo < $hi)} {
        return {}
    }
    set n [llength $counts]
    set edges {}
    for {set i 0} {$i <= $n} {incr i} {
        lappend edges [expr {$lo + ($hi - $lo) * $i / double($n)}]
    }
    return [dict create edges $edges fractions [lmap c $counts {expr {double($c) / $total}}]]
}

# ::pvr::gui::loadDataset --
#   Selects dataset `name` and renders a frame. Before that frame the view
#   takes the server's camera for it and the editor its value range
#   (readScene), and the editor's points go out in that range.
proc ::pvr::gui::loadDataset {name} {
    variable session
    variable opt
    variable tfPending
    variable rangePending
    set opt(dataset) $name
    # Until the server has the new data's histogram (readScene).
    ::pvr::gui::tfeditor::histogram .ctl.tf.editor {} {}
    lassign [split $opt(imagesz) x] w h
    if {[catch {$session set -dataset $name -imagesz $w,$h} message]} {
        status "dataset $name: $message" error
        return
    }
    # Exactly this one volume: a volume list is gone (docs/pvrsh.md).
    ::pvr::gui::volumes::reset
    ::pvr::gui::stat::clear .stat.c
    status "dataset $name"
    set rangePending 1
    set tfPending 1
    ::pvr::gui::view::sceneChanged
    ::pvr::gui::view::request
}

# ::pvr::gui::serverStatus --
#   The server's status entries (`list status`, remote): a dict, empty
#   while a request is in flight or when the session is not open.
proc ::pvr::gui::serverStatus {} {
    variable session
    if {[catch {dict get [$session list status] remote} remote]} {
        status "status: $remote" error
        return {}
    }
    return $remote
}

# ::pvr::gui::readScene --
#   The view's camera source, asked before a request when the dataset has
#   changed: returns the server's camera {eye look_at up} ({} when it has
#   none yet), and fits the editor to the data's value range and
#   histogram for a new dataset.
proc ::pvr::gui::readScene {} {
    variable opt
    variable rangePending
    set remote [serverStatus]
    showTimeSteps $remote
    if {$rangePending && [dict exists $remote value_range]} {
        lassign [dict get $remote value_range] lo hi
        if {$lo < $hi} {
            set opt(tflo) $lo
            set opt(tfhi) $hi
            ::pvr::gui::tfeditor::range .ctl.tf.editor $lo $hi
        }
        set hist [serverHistogram $remote]
        if {[dict exists $hist edges]} {
            ::pvr::gui::tfeditor::histogram .ctl.tf.editor [dict get $hist edges] [dict get $hist fractions]
        }
        set rangePending 0
    }
    set camera {}
    foreach key {camera_eye camera_look_at camera_up} {
        if {[dict exists $remote $key]} {
            lappend camera [dict get $remote $key]
        }
    }
    return [expr {[llength $camera] == 3 ? $camera : {}}]
}

# ::pvr::gui::showTimeSteps --
#   Shows the time slider, spanning the dataset's steps at the session's
#   step, when the server's status says the dataset has more than one
#   (`timesteps`); hides it otherwise.
proc ::pvr::gui::showTimeSteps {remote} {
    variable timeValue
    variable timestep
    set steps [expr {[dict exists $remote timesteps] ? [dict get $remote timesteps] : 1}]
    if {$steps > 1} {
        .ctl.time.scale configure -to [expr {$steps - 1}]
        set timestep [dict get $remote timestep]
        set timeValue $timestep
        pack .ctl.time -after .ctl.data -fill x -pady 3
    } else {
        pack forget .ctl.time
    }
}

# ::pvr::gui::timeStepMoved --
#   The slider moved to `value`: when that is another whole step, the
#   session shows it (set -timestep) and renders the current view.
proc ::pvr::gui::timeStepMoved {value} {
    variable session
    variable timestep
    set step [expr {int(round($value))}]
    if {$step == $timestep} {
        return
    }
    if {[catch {$session set -timestep $step} message]} {
        status "time step $step: $message" error
        return
    }
    set timestep $step
    ::pvr::gui::view::request
}

proc ::pvr::gui::applyImageSize {} {
    variable session
    variable opt
    if {![regexp {^\s*(\d+)\s*[x,]\s*(\d+)\s*$} $opt(imagesz) -> w h]} {
        status "image size must be WxH, got '$opt(imagesz)'" error
        return
    }
    if {[catch {$session set -imagesz $w,$h} message]} {
        status "image size: $message" error
        return
    }
    ::pvr::gui::view::request
}

# ---- Transfer function ----

proc ::pvr::gui::applyTfRange {} {
    variable opt
    if {[catch {::pvr::gui::tfeditor::range .ctl.tf.editor $opt(tflo) $opt(tfhi)} message]} {
        status $message error
        return
    }
    tfChanged [::pvr::gui::tfeditor::points .ctl.tf.editor]
}

proc ::pvr::gui::choosePreset {} {
    set file [tk_getOpenFile -title "ParaView transfer-function preset" \
                  -filetypes {{{ParaView presets} {.json}} {{All files} *}}]
    if {$file ne ""} {
        loadPreset $file
    }
}

# ::pvr::gui::loadPreset --
#   Sends the ParaView preset `file` (`:s set -tfpreset`); the server reads
#   it, and its points, as `list status` reports them, go into the editor,
#   which renders a frame. Results: 1 when the editor holds the preset.
proc ::pvr::gui::loadPreset {file} {
    variable session
    variable opt
    variable connected
    if {!$connected} {
        status "preset: not connected" error
        return 0
    }
    if {$::pvr::gui::view::busy} {
        status "preset: a request is in flight; load the preset when it ends" error
        return 0
    }
    set errors $::pvr::gui::errors
    if {[catch {$session {*}[::pvr::gui::volumes::tfWords -tfpreset $file]} message]} {
        status "preset: $message" error
        return 0
    }
    if {[::pvr::gui::volumes::inList]} {
        # The server's status reports the first volume's points only: the
        # editor keeps its own, and the volume shows the preset.
        status "preset [file tail $file] on volume $::pvr::gui::volumes::selected"
        ::pvr::gui::volumes::refresh
        requestFrame
        return 1
    }
    set remote [serverStatus]
    # A preset the server refused was reported on the status line meanwhile.
    if {$::pvr::gui::errors > $errors} {
        return 0
    }
    if {![dict exists $remote transfer_function]} {
        status "preset $file: the server reports no transfer function" error
        return 0
    }
    set points [dict get $remote transfer_function]
    status "preset [file tail $file]"
    if {[catch {
        # The editor's range covers the data and every point of the preset.
        set lo [lindex $points 0]
        set hi [lindex $points end-4]
        if {[dict exists $remote value_range]} {
            lassign [dict get $remote value_range] vlo vhi
            set lo [expr {min($lo, $vlo)}]
            set hi [expr {max($hi, $vhi)}]
        }
        ::pvr::gui::tfeditor::range .ctl.tf.editor $lo $hi
        # Setting the points notifies tfChanged, which renders with them.
        ::pvr::gui::tfeditor::points .ctl.tf.editor $points
    } message]} {
        status "preset $file: $message" error
        return 0
    }
    set opt(tflo) $lo
    set opt(tfhi) $hi
    return 1
}

# ::pvr::gui::tfChanged --
#   The editor changed: the newest points go out with the next request
#   (::pvr::gui::send), which is now when idle, otherwise when the request
#   in flight ends.
proc ::pvr::gui::tfChanged {points} {
    variable tfPending
    variable connected
    if {!$connected || $::pvr::gui::volumes::loading} {
        return
    }
    set tfPending 1
    ::pvr::gui::view::request
}

# ---- Requests and arrivals ----

# ::pvr::gui::send --
#   The view's sender: `render frame` or `render rotate AXIS K,K:N`, timed
#   from here to the frame in the photo. Sends pending TF points first.
proc ::pvr::gui::send {args} {
    variable session
    variable request
    variable tfPending
    variable connected
    if {!$connected} {
        return -code error -errorcode {PVR GUI NOTCONNECTED} "not connected: press Connect"
    }
    if {$tfPending} {
        set tfPending 0
        $session {*}[::pvr::gui::volumes::tfWords -tf [::pvr::gui::tfeditor::points .ctl.tf.editor]]
        ::pvr::gui::volumes::describe
    }
    set start [clock microseconds]
    set total [$session render {*}$args]
    set request [dict create kind frame done 0 total $total start $start]
    status "rendering\u2026" busy
}

# ::pvr::gui::requestFrame --
#   A frame of the current view (::pvr::gui::view::request): progressive
#   (a coarse frame, then the full one) or `full` (one frame, for saving);
#   a failure is a message on the status line. Results: 1 when sent or
#   queued.
proc ::pvr::gui::requestFrame {{quality progressive}} {
    if {[catch {::pvr::gui::view::request [expr {$quality eq "progressive"}]} message]} {
        status "render: $message" error
        return 0
    }
    return 1
}

proc ::pvr::gui::renderSequence {} {
    variable session
    variable opt
    variable request
    variable connected
    if {!$connected} {
        status "render rotate: not connected: press Connect" error
        return 0
    }
    if {$::pvr::gui::view::busy} {
        status "a request is in flight; cancel it first" error
        return 0
    }
    set start [clock microseconds]
    # The sequence turns the view on screen, not the one reported before a drag.
    if {[catch {::pvr::gui::view::commit} message]} {
        status "render rotate: $message" error
        return 0
    }
    if {[catch {$session render rotate $opt(axis) $opt(range)} total]} {
        status "render rotate: $total" error
        return 0
    }
    set ::pvr::gui::view::busy 1
    set request [dict create kind sequence done 0 total $total start $start]
    set ::pvr::gui::progress 0
    .bar.progress configure -maximum $total
    status "rotate $opt(axis) $opt(range): 0/$total frames" busy
    return 1
}

proc ::pvr::gui::cancel {} {
    variable session
    if {[catch {$session cancel} n]} {
        status "cancel: $n" error
    }
}

# ::pvr::gui::onFrame --
#   `:s image callback`: the frame is in the photo already. Updates the
#   graph, the progress bar and the status line.
proc ::pvr::gui::onFrame {frame timing} {
    variable request
    variable lastLatency
    variable shownSize
    # The view: a new size asks the window for room, then the frame is fitted.
    set size [list [::image width $::pvr::gui::image] [::image height $::pvr::gui::image]]
    if {![info exists shownSize] || $shownSize ne $size} {
        set shownSize $size
        ::pvr::gui::fit::request
    }
    ::pvr::gui::fit::refit
    set now [clock microseconds]
    dict incr request done
    set done [dict get $request done]
    set total [dict get $request total]
    set elapsed [expr {($now - [dict get $request start]) / 1e6}]
    # The graph's arrival tick: from the request for a single frame, from
    # the previous frame within a sequence.
    set since [expr {[dict exists $request last] ? [dict get $request last] : [dict get $request start]}]
    dict set request last $now
    dict set timing arrival [expr {($now - $since) / 1e6}]
    ::pvr::gui::stat::add .stat.c $frame $timing
    # An interactive render's coarse frame: the next view may go out.
    # lastQuality and coarseFrames are for the status of tests.
    variable lastQuality [dict get $timing quality]
    if {$lastQuality eq "coarse"} {
        incr ::pvr::gui::coarseFrames
        ::pvr::gui::view::firstFrame
    }
    if {[dict get $request kind] eq "sequence"} {
        set ::pvr::gui::progress $done
        set fps [expr {$elapsed > 0 ? $done / $elapsed : 0}]
        set left [expr {$fps > 0 ? ($total - $done) / $fps : 0}]
        status [format "frame %d: %d/%d, %.1f fps, %.1f s left" $frame $done $total $fps $left] busy
    } else {
        set lastLatency $elapsed
        set ::pvr::gui::progress 0
        status [format "frame %d in %.0f ms (render %.0f ms)" $frame [expr {$elapsed * 1e3}] \
                    [expr {[::pvr::gui::stat::phaseValue $timing rend] * 1e3}]]
    }
}

# ::pvr::gui::onNotify --
#   `:s notify`: done N, cancelled N, or error MESSAGE CODE. A request ends
#   with done or cancelled; the next coalesced request goes out then.
proc ::pvr::gui::onNotify {event args} {
    variable request
    switch -- $event {
        done - cancelled {
            if {[dict get $request kind] eq "sequence"} {
                set done [dict get $request done]
                set secs [expr {([clock microseconds] - [dict get $request start]) / 1e6}]
                status [format "sequence %s: %d frames in %.1f s" $event $done $secs]
            }
            dict set request kind none
            ::pvr::gui::render::requestEnded $event
            ::pvr::gui::layout::requestEnded
            ::pvr::gui::view::finished
        }
        error {
            lassign $args message code
            if {[lrange $code 0 1] eq {PVR CONNECT}} {
                markConnected 0
            }
            status "server: $message" error
            # A dead job: the session is over (checked outside this callback).
            after idle ::pvr::gui::checkConnection
        }
    }
}
