# gui_layout.tcl -- the cluster and group configuration window of the PVR GUI
# (the left window of Figure 13 in paper 003).
#
# Rendering clusters hold the whole dataset split into bricks; clusters in
# one group share the scanlines of a frame, groups take different frames
# (`:s set -cluster r,RANKS -group 0,0,1,1`). Compositing is done by the
# rendering ranks themselves, or by separate compositing clusters
# (`-cluster c -group 0,0`). The strategy and decomposition boxes offer
# what the server reports (`list status`: strategies, decompositions) and
# show what is in force (strategy, decomposition). The window also asks the
# server what a layout costs: dataset memory per cluster and the estimated
# compositing latency (`:s performance memory cluster`,
# `:s performance comp cluster latency`).

namespace eval ::pvr::gui::layout {
    # The form's variables, bound to the widgets.
    variable form
    array set form {
        renderRanks 1
        renderGroups 0
        composite self
        compositeGroups 0
        strategy ""
        decomposition ""
    }
    # Strategy and decomposition in force, as the server last reported them:
    # the form's are sent only when they differ.
    variable inForce
    array set inForce {strategy "" decomposition ""}
    # Apply: the layout goes out with the next request (pvrsh sends it
    # before the render), so the window shows it when that request ends.
    variable refreshPending 0
    variable session ""
}

# ::pvr::gui::layout::show --
#   Opens (or raises) the window .layout for session command `session`.
proc ::pvr::gui::layout::show {session} {
    set w .layout
    if {[winfo exists $w]} {
        wm deiconify $w
        raise $w
        refresh $session
        return $w
    }
    toplevel $w
    wm title $w "PVR clusters and groups"

    # Step 1: the form.
    set f [ttk::labelframe $w.render -text "Rendering clusters" -padding 6]
    ttk::label $f.rl -text "Ranks per cluster"
    ttk::spinbox $f.rs -from 1 -to 1024 -width 6 -textvariable ::pvr::gui::layout::form(renderRanks)
    ttk::label $f.gl -text "Group of each cluster"
    ttk::entry $f.ge -width 16 -textvariable ::pvr::gui::layout::form(renderGroups)
    ttk::label $f.help -foreground #555555 -wraplength 300 -justify left \
        -text "One number per cluster: 0,0,1,1 is four clusters in two groups. Clusters of a group split the scanlines of a frame; groups render different frames."
    grid $f.rl $f.rs -sticky w -pady 2
    grid $f.gl $f.ge -sticky w -pady 2
    grid $f.help - -sticky w -pady 2

    set c [ttk::labelframe $w.comp -text "Compositing" -padding 6]
    ttk::radiobutton $c.self -text "Rendering ranks composite (with the strategy below)" \
        -variable ::pvr::gui::layout::form(composite) -value self
    ttk::radiobutton $c.sep -text "Separate compositing clusters, groups:" \
        -variable ::pvr::gui::layout::form(composite) -value separate
    ttk::entry $c.ge -width 10 -textvariable ::pvr::gui::layout::form(compositeGroups)
    ttk::label $c.sl -text "Strategy"
    ttk::combobox $c.sc -state readonly -width 14 -textvariable ::pvr::gui::layout::form(strategy)
    ttk::label $c.dl -text "Decomposition"
    ttk::combobox $c.dc -state readonly -width 14 -textvariable ::pvr::gui::layout::form(decomposition)
    grid $c.self - -sticky w
    grid $c.sep $c.ge -sticky w
    grid $c.sl $c.sc -sticky w -pady 2
    grid $c.dl $c.dc -sticky w -pady 2

    # Step 2: what the server says about it.
    set r [ttk::labelframe $w.report -text "Server" -padding 6]
    text $r.t -width 52 -height 10 -wrap word -font TkFixedFont -relief flat -background #f4f4f4
    ttk::frame $r.b
    ttk::button $r.b.mem -text "Memory per cluster" -command [list ::pvr::gui::layout::query $session memory]
    ttk::button $r.b.lat -text "Compositing latency" -command [list ::pvr::gui::layout::query $session comp]
    ttk::button $r.b.ref -text "Refresh" -command [list ::pvr::gui::layout::refresh $session]
    pack $r.b.mem $r.b.lat $r.b.ref -side left -padx 2
    pack $r.b -anchor w
    pack $r.t -fill both -expand 1

    ttk::frame $w.buttons
    ttk::button $w.buttons.apply -text "Apply" -command [list ::pvr::gui::layout::apply $session]
    ttk::button $w.buttons.close -text "Close" -command [list wm withdraw $w]
    pack $w.buttons.close $w.buttons.apply -side right -padx 4
    pack $w.render $w.comp $w.report -fill x -padx 6 -pady 4
    pack $w.buttons -fill x -padx 6 -pady 6
    wm protocol $w WM_DELETE_WINDOW [list wm withdraw $w]
    # Beside the main window (a window manager may place it elsewhere).
    wm geometry $w +[expr {[winfo rootx .] + [winfo width .] + 12}]+[winfo rooty .]
    refresh $session
    return $w
}

# ::pvr::gui::layout::report --
#   Replaces the server text with `text`.
proc ::pvr::gui::layout::report {text} {
    if {![winfo exists .layout.report.t]} {
        return
    }
    .layout.report.t delete 1.0 end
    .layout.report.t insert end $text
}

# ::pvr::gui::layout::refresh --
#   Shows the layout in force (`:s list status`), fills the form from it,
#   and offers the server's strategies and decompositions.
proc ::pvr::gui::layout::refresh {session} {
    variable form
    variable inForce
    if {[catch {$session list status} status]} {
        report "status: $status"
        return
    }
    set lines [list "state [dict get $status state], [dict get $status ranks] ranks started"]
    set renderGroups {}
    set compositeGroups {}
    foreach cluster [dict get $status layout] {
        lassign $cluster role ranks group
        lappend lines [format "  %-10s %4s ranks  group %s" $role [expr {$ranks == 0 ? "auto" : $ranks}] $group]
        if {$role eq "render"} {
            lappend renderGroups $group
            if {$ranks > 0} {
                set form(renderRanks) $ranks
            }
        } elseif {$role eq "composite"} {
            lappend compositeGroups $group
        }
    }
    if {$renderGroups ne {}} {
        set form(renderGroups) [join $renderGroups ,]
    }
    if {$compositeGroups ne {}} {
        set form(composite) separate
        set form(compositeGroups) [join $compositeGroups ,]
    }
    set remote [dict get $status remote]
    foreach {key names box} {strategy strategies .layout.comp.sc decomposition decompositions .layout.comp.dc} {
        if {[dict exists $remote $names]} {
            $box configure -values [dict get $remote $names]
        }
        if {[dict exists $remote $key]} {
            set inForce($key) [dict get $remote $key]
            set form($key) $inForce($key)
            lappend lines "  $key $inForce($key)"
        }
    }
    report [join $lines \n]
}

# ::pvr::gui::layout::apply --
#   Sends the form as -cluster/-group, -strategy and -decomposition settings.
proc ::pvr::gui::layout::apply {session} {
    variable form
    variable inForce
    set settings [list -cluster r,$form(renderRanks) -group $form(renderGroups)]
    foreach key {strategy decomposition} {
        if {$form($key) ne "" && $form($key) ne $inForce($key)} {
            lappend settings -$key $form($key)
        }
    }
    if {[catch {
        $session set {*}$settings
        if {$form(composite) eq "separate"} {
            $session set -cluster c -group $form(compositeGroups)
        }
    } message]} {
        report "apply: $message"
        ::pvr::gui::status "layout not applied: $message" error
        return
    }
    ::pvr::gui::status "layout applied: [join $settings { }]"
    variable refreshPending 1
    set ::pvr::gui::layout::session $session
    report "applying: [join $settings { }] (the layout in force shows when the next frame has rendered)"
    ::pvr::gui::requestFrame
}

# ::pvr::gui::layout::requestEnded --
#   A request ended: after Apply, the window shows the layout now in force.
proc ::pvr::gui::layout::requestEnded {} {
    variable refreshPending
    variable session
    if {!$refreshPending} {
        return
    }
    set refreshPending 0
    # Outside the notify callback: refresh asks the server.
    after idle [list ::pvr::gui::layout::refresh $session]
}

# ::pvr::gui::layout::human --
#   One value of a performance answer in human units by its key: bytes as
#   KB, MB or GB, seconds as ms (or s), other numbers with 4 digits.
proc ::pvr::gui::layout::human {key value} {
    if {![string is double -strict $value]} {
        return $value
    }
    if {[string match *bytes* $key]} {
        foreach {unit size} {GB 1073741824.0 MB 1048576.0 KB 1024.0} {
            if {abs($value) >= $size} {
                return [format "%.1f %s" [expr {$value / $size}] $unit]
            }
        }
        return [format "%d B" [expr {wide($value)}]]
    }
    if {[string match *seconds* $key] || [string match *_s $key]} {
        if {abs($value) >= 1} {
            return [format "%.2f s" $value]
        }
        return [format "%.2f ms" [expr {$value * 1e3}]]
    }
    if {[string is wide -strict $value]} {
        return $value
    }
    return [format %.4g $value]
}

# ::pvr::gui::layout::humanLine --
#   A performance dict as one line of `key value` pairs in human units.
proc ::pvr::gui::layout::humanLine {item} {
    set fields {}
    dict for {k v} $item {
        if {[catch {dict size $v}] || [llength $v] < 2 || [string is double -strict $v]} {
            lappend fields "$k [human $k $v]"
        } else {
            lappend fields "$k {[humanLine $v]}"
        }
    }
    return [join $fields {  }]
}

# ::pvr::gui::layout::query --
#   `:s performance memory cluster` or `:s performance comp cluster latency`,
#   shown as one line per cluster.
proc ::pvr::gui::layout::query {session what} {
    set words [expr {$what eq "memory" ? {memory cluster} : {comp cluster latency}}]
    ::pvr::gui::status "asking the server: performance $words"
    if {[catch {$session performance {*}$words} answer]} {
        report "performance $words: $answer"
        ::pvr::gui::status "performance $words: $answer" error
        return
    }
    set lines [list "performance $words:"]
    foreach item $answer {
        if {[catch {dict size $item}]} {
            lappend lines "  $item"
            continue
        }
        lappend lines "  [humanLine $item]"
    }
    report [join $lines \n]
    ::pvr::gui::status "performance $words: [llength $answer] clusters"
}
