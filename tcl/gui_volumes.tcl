# gui_volumes.tcl -- the GUI's volumes (issue 12): the scene's volumes as
# `:s volume list` gives them, each with a checkbutton for its visibility
# (`volume configure NAME -visible`) and a radiobutton choosing the volume
# whose transfer function the editor edits (`volume configure NAME -tf`);
# an "Add volume" menu of the catalog's datasets adds one
# (`volume add NAME -dataset D`). While the session shows one dataset
# (`set -dataset`, the GUI's dataset box) the panel is hidden and the editor
# sends `set -tf`, as before; choosing a dataset in the box goes back to
# that.
#
# Usage (gui.tcl):
#   ::pvr::gui::volumes::build .ctl.vols        ;# the panel (not packed)
#   ::pvr::gui::volumes::addButton .ctl.data.addvol
#   ::pvr::gui::volumes::setDatasets $names     ;# the catalog, after connect
#   ::pvr::gui::volumes::tfWords -tf $points    ;# the session words that send the editor's points
#   ::pvr::gui::volumes::reset                  ;# a dataset was chosen: one volume again

namespace eval ::pvr::gui::volumes {
    # The volume the editor edits; "" while the session shows one dataset.
    variable selected ""
    # name -> 0 or 1, bound to the checkbuttons.
    variable visible
    array set visible {}
    # 1 while the editor takes a volume's points: no send for that.
    variable loading 0
}

# ::pvr::gui::volumes::build --
#   Creates the (unpacked) panel `f`; refresh fills and shows it.
proc ::pvr::gui::volumes::build {f} {
    ttk::labelframe $f -text "Volumes (tick: visible; edit: the transfer function below)" -padding 4
    ttk::frame $f.rows
    pack $f.rows -fill x
    return $f
}

# ::pvr::gui::volumes::addButton --
#   Creates menubutton `b`, whose menu adds a dataset of the catalog as a
#   volume of the scene.
proc ::pvr::gui::volumes::addButton {b} {
    ttk::menubutton $b -text "Add volume" -menu $b.m
    menu $b.m -tearoff 0
    return $b
}

# ::pvr::gui::volumes::setDatasets --
#   The catalog's dataset names, one menu entry each.
proc ::pvr::gui::volumes::setDatasets {names} {
    set m .ctl.data.addvol.m
    $m delete 0 end
    foreach name $names {
        $m add command -label $name -command [list ::pvr::gui::volumes::add $name]
    }
}

# ::pvr::gui::volumes::inList --
#   1 when the session has a volume list (a volume command made it), 0
#   while it shows one dataset (`set -dataset`, which then has a value) or
#   none. Asked of the session each time, so a refused `volume add` (the
#   session is back to what the server holds) counts as it should.
proc ::pvr::gui::volumes::inList {} {
    set session $::pvr::gui::session
    expr {[$session set -dataset] eq "" && [llength [$session volume list]] > 0}
}

# ::pvr::gui::volumes::uniqueName --
#   A volume name for dataset `dataset`: its file's stem, numbered when the
#   scene has a volume of that name already.
proc ::pvr::gui::volumes::uniqueName {dataset} {
    set names [lmap v [$::pvr::gui::session volume list] {dict get $v name}]
    set stem [file rootname [file tail $dataset]]
    regsub {\.series$} $stem {} stem
    set name $stem
    for {set i 2} {$name in $names} {incr i} {
        set name $stem$i
    }
    return $name
}

# ::pvr::gui::volumes::add --
#   Adds dataset `dataset` as a volume (a session of one dataset keeps it as
#   the volume named "volume"), selects it and renders. Results: its name,
#   or "" when the session refused the command.
proc ::pvr::gui::volumes::add {dataset} {
    set session $::pvr::gui::session
    if {!$::pvr::gui::connected} {
        ::pvr::gui::status "add volume: not connected (press Connect)" error
        return ""
    }
    set name [uniqueName $dataset]
    if {[catch {$session volume add $name -dataset $dataset} message]} {
        ::pvr::gui::status "add volume: $message" error
        return ""
    }
    ::pvr::gui::status "volume $name: $dataset"
    refresh
    select $name
    # The new volume shows what the editor shows: its points, over the
    # volume's own range, go out with the frame.
    set ::pvr::gui::tfPending 1
    ::pvr::gui::view::sceneChanged
    ::pvr::gui::requestFrame
    return $name
}

# ::pvr::gui::volumes::refresh --
#   Rebuilds the panel's rows from `volume list` and shows the panel while
#   the session has a volume list, hides it otherwise.
proc ::pvr::gui::volumes::refresh {} {
    variable selected
    variable visible
    set rows .ctl.vols.rows
    foreach child [winfo children $rows] {
        destroy $child
    }
    array unset visible
    set volumes [expr {[inList] ? [$::pvr::gui::session volume list] : {}}]
    if {[llength $volumes] == 0} {
        pack forget .ctl.vols
        return
    }
    set names {}
    set i 0
    foreach v $volumes {
        set name [dict get $v name]
        lappend names $name
        set visible($name) [dict get $v visible]
        ttk::radiobutton $rows.e$i -text edit -value $name -variable ::pvr::gui::volumes::selected \
            -command [list ::pvr::gui::volumes::select $name]
        ttk::checkbutton $rows.v$i -text $name -variable ::pvr::gui::volumes::visible($name) \
            -command [list ::pvr::gui::volumes::toggle $name]
        ttk::label $rows.d$i -text "[dict get $v dataset] ([dict get $v tf])"
        ttk::button $rows.r$i -text "\u00d7" -width 2 -command [list ::pvr::gui::volumes::remove $name]
        grid $rows.e$i $rows.v$i $rows.d$i $rows.r$i -sticky w -padx 2
        incr i
    }
    if {$selected ni $names} {
        set selected [lindex $names 0]
    }
    pack .ctl.vols -after .ctl.data -fill x -pady 3
}

# ::pvr::gui::volumes::describe --
#   Updates each row's description (dataset, transfer function summary)
#   after a change that keeps the rows (a transfer function sent).
proc ::pvr::gui::volumes::describe {} {
    if {![inList]} {
        return
    }
    set i 0
    foreach v [$::pvr::gui::session volume list] {
        if {[winfo exists .ctl.vols.rows.d$i]} {
            .ctl.vols.rows.d$i configure -text "[dict get $v dataset] ([dict get $v tf])"
        }
        incr i
    }
}

# ::pvr::gui::volumes::toggle --
#   Volume `name`'s checkbutton: shows or hides it and renders.
proc ::pvr::gui::volumes::toggle {name} {
    variable visible
    if {[catch {$::pvr::gui::session volume configure $name -visible $visible($name)} message]} {
        ::pvr::gui::status "volume $name: $message" error
        refresh
        return
    }
    ::pvr::gui::status "volume $name [expr {$visible($name) ? "shown" : "hidden"}]"
    ::pvr::gui::requestFrame
}

# ::pvr::gui::volumes::remove --
#   Takes volume `name` out of the scene and renders.
proc ::pvr::gui::volumes::remove {name} {
    if {[catch {$::pvr::gui::session volume remove $name} message]} {
        ::pvr::gui::status "remove volume: $message" error
        return
    }
    ::pvr::gui::status "volume $name removed"
    refresh
    select $::pvr::gui::volumes::selected
    ::pvr::gui::view::sceneChanged
    ::pvr::gui::requestFrame
}

# ::pvr::gui::volumes::select --
#   The editor edits volume `name` from now on: it spans the volume's value
#   range (the server's status, key `volumes`, when it can answer now), with
#   the server's histogram behind it for the first volume (the only one the
#   status counts one for) and none for another, and shows the volume's
#   points when it has them as points.
proc ::pvr::gui::volumes::select {name} {
    variable selected
    variable loading
    set selected $name
    if {[catch {$::pvr::gui::session volume configure $name} volume]} {
        ::pvr::gui::status "volume $name: $volume" error
        return
    }
    set editor .ctl.tf.editor
    set loading 1
    catch {
        if {!$::pvr::gui::view::busy} {
            set remote [::pvr::gui::serverStatus]
            if {[dict exists $remote volumes]} {
                set hist {}
                if {[dict get [lindex [dict get $remote volumes] 0] name] eq $name} {
                    set hist [::pvr::gui::serverHistogram $remote]
                }
                if {[dict exists $hist edges]} {
                    ::pvr::gui::tfeditor::histogram $editor [dict get $hist edges] [dict get $hist fractions]
                } else {
                    ::pvr::gui::tfeditor::histogram $editor {} {}
                }
                foreach v [dict get $remote volumes] {
                    if {[dict get $v name] eq $name && [dict exists $v value_range]} {
                        lassign [dict get $v value_range] lo hi
                        if {$lo < $hi} {
                            ::pvr::gui::tfeditor::range $editor $lo $hi
                            set ::pvr::gui::opt(tflo) $lo
                            set ::pvr::gui::opt(tfhi) $hi
                        }
                    }
                }
            }
        }
        if {[llength [dict get $volume points]] >= 10} {
            ::pvr::gui::tfeditor::points $editor [dict get $volume points]
        }
    }
    set loading 0
    .ctl.tf configure -text "Transfer function of $name (drag, click to add, right-click to remove)"
}

# ::pvr::gui::volumes::tfWords --
#   The session words that send the edited transfer function's `option`
#   (-tf points, -tfpreset FILE): `volume configure SELECTED` with a volume
#   list, else `set`.
proc ::pvr::gui::volumes::tfWords {option value} {
    variable selected
    if {$selected ne "" && [inList]} {
        return [list volume configure $selected $option $value]
    }
    return [list set $option $value]
}

# ::pvr::gui::volumes::reset --
#   The session shows one dataset again (`set -dataset`): no list, no panel.
proc ::pvr::gui::volumes::reset {} {
    variable selected
    set selected ""
    if {[winfo exists .ctl.vols]} {
        refresh
        .ctl.tf configure -text "Transfer function (drag, click to add, right-click to remove)"
    }
}
