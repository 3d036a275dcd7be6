# tfeditor.tcl -- a transfer-function editor on a Tk canvas.
#
# The transfer function is a list of control points {scalar r g b opacity}
# (the -tf option of `:s set`), linear between points. The editor shows the
# points over the data's histogram (log scale) when it is known, otherwise
# over a plain ramp, with the opacity curve through them and a colour strip
# below. Points are kept as a fraction u of the scalar range, so changing the
# range (another dataset) keeps the shape.
#
#   drag a point        move it (scalar between its neighbours; opacity)
#   click empty space   add a point there, coloured as the curve is there
#   double-click point  choose its colour
#   right-click point   remove it (two points always stay)
#
# Usage:
#   ::pvr::gui::tfeditor::create .tf -command applyProc ;# canvas .tf
#   ::pvr::gui::tfeditor::range .tf -1024 2986
#   ::pvr::gui::tfeditor::histogram .tf $edges $fractions
#   ::pvr::gui::tfeditor::points .tf   ;# {s r g b a s r g b a ...}
# applyProc is called with the points (as `points` returns them) after every
# change, while dragging too; callers coalesce renders themselves.

namespace eval ::pvr::gui::tfeditor {
    # Per editor `w`: state($w,points) {{u r g b a} ...} sorted by u;
    # state($w,range) {lo hi}; state($w,hist) {edges fractions} or {};
    # state($w,command); state($w,drag) index of the point being dragged.
    variable state
    array set state {}
    # Margins of the plot inside the canvas, and the colour strip's height.
    variable pad 8
    variable strip 14
    variable radius 5
}

# ::pvr::gui::tfeditor::create --
#   Creates canvas `w` as an editor with a default ramp.
# Arguments: w (new canvas path); -command PROC; -width, -height pixels.
# Results: w.
proc ::pvr::gui::tfeditor::create {w args} {
    variable state
    set opts [dict merge {-command {} -width 360 -height 150} $args]
    canvas $w -width [dict get $opts -width] -height [dict get $opts -height] \
        -background white -highlightthickness 0 -cursor crosshair
    set state($w,points) {{0.0 0.0 0.0 0.0 0.0} {0.3 0.6 0.45 0.3 0.0} {0.6 1.0 0.9 0.8 0.5} {1.0 1.0 1.0 1.0 0.9}}
    set state($w,range) {0.0 1.0}
    set state($w,hist) {}
    set state($w,command) [dict get $opts -command]
    set state($w,drag) -1
    bind $w <Configure> [list ::pvr::gui::tfeditor::redraw $w]
    bind $w <ButtonPress-1> [list ::pvr::gui::tfeditor::press $w %x %y]
    bind $w <B1-Motion> [list ::pvr::gui::tfeditor::motion $w %x %y]
    bind $w <ButtonRelease-1> [list ::pvr::gui::tfeditor::release $w]
    bind $w <Double-Button-1> [list ::pvr::gui::tfeditor::chooseColour $w %x %y]
    bind $w <ButtonPress-3> [list ::pvr::gui::tfeditor::remove $w %x %y]
    bind $w <Destroy> [list array unset ::pvr::gui::tfeditor::state $w,*]
    redraw $w
    return $w
}

# ---- Accessors ----

# ::pvr::gui::tfeditor::range --
#   Sets the scalar range {lo hi} shown (lo < hi), or returns it.
proc ::pvr::gui::tfeditor::range {w args} {
    variable state
    if {[llength $args] == 2} {
        lassign $args lo hi
        if {![string is double -strict $lo] || ![string is double -strict $hi] || $lo >= $hi} {
            return -code error -errorcode {PVR ARGS RANGE} "tf range needs lo < hi, got '$lo $hi'"
        }
        set state($w,range) [list [expr {double($lo)}] [expr {double($hi)}]]
        redraw $w
    }
    return $state($w,range)
}

# ::pvr::gui::tfeditor::histogram --
#   Sets the histogram drawn behind the points: bin edges (n+1 scalars) and
#   n fractions. Empty lists: no histogram (a plain ramp).
proc ::pvr::gui::tfeditor::histogram {w edges fractions} {
    variable state
    set state($w,hist) {}
    if {[llength $fractions] > 0 && [llength $edges] == [llength $fractions] + 1} {
        set state($w,hist) [list $edges $fractions]
    }
    redraw $w
}

# ::pvr::gui::tfeditor::points --
#   With no argument, the points in scalars: {s r g b a s r g b a ...}.
#   With a flat list of 5-tuples in scalars, replaces the points (clamped
#   into the range) and notifies -command.
proc ::pvr::gui::tfeditor::points {w {flat ""}} {
    variable state
    lassign $state($w,range) lo hi
    if {$flat ne ""} {
        if {[llength $flat] % 5 != 0 || [llength $flat] < 10} {
            return -code error -errorcode {PVR ARGS TF} "tf points: need at least two {scalar r g b opacity} points"
        }
        set pts {}
        foreach {s r g b a} $flat {
            lappend pts [list [clamp [expr {($s - $lo) / ($hi - $lo)}]] $r $g $b [clamp $a]]
        }
        set state($w,points) [lsort -real -index 0 $pts]
        redraw $w
        changed $w
    }
    set out {}
    foreach p $state($w,points) {
        lassign $p u r g b a
        lappend out [expr {$lo + $u * ($hi - $lo)}] $r $g $b $a
    }
    return $out
}

# ::pvr::gui::tfeditor::normalized --
#   The points as {u r g b a} with u in [0, 1] (tests read it).
proc ::pvr::gui::tfeditor::normalized {w} {
    variable state
    return $state($w,points)
}

# ---- Geometry ----

proc ::pvr::gui::tfeditor::clamp {v {lo 0.0} {hi 1.0}} {
    return [expr {min($hi, max($lo, double($v)))}]
}

# The plot box {x0 y0 x1 y1}: y0 is opacity 1, y1 opacity 0.
proc ::pvr::gui::tfeditor::box {w} {
    variable pad
    variable strip
    set width [winfo width $w]
    set height [winfo height $w]
    if {$width <= 1} {
        set width [$w cget -width]
        set height [$w cget -height]
    }
    return [list $pad $pad [expr {$width - $pad}] [expr {$height - $pad - $strip - 4}]]
}

# Canvas position of point {u r g b a}.
proc ::pvr::gui::tfeditor::toCanvas {w u a} {
    lassign [box $w] x0 y0 x1 y1
    return [list [expr {$x0 + $u * ($x1 - $x0)}] [expr {$y1 - $a * ($y1 - $y0)}]]
}

# {u a} of a canvas position, clamped into the box.
proc ::pvr::gui::tfeditor::fromCanvas {w x y} {
    lassign [box $w] x0 y0 x1 y1
    return [list [clamp [expr {double($x - $x0) / ($x1 - $x0)}]] [clamp [expr {double($y1 - $y) / ($y1 - $y0)}]]]
}

# The index of the point within radius+2 pixels of (x, y), or -1.
proc ::pvr::gui::tfeditor::hit {w x y} {
    variable state
    variable radius
    set best -1
    set bestD [expr {($radius + 2) ** 2}]
    set i 0
    foreach p $state($w,points) {
        lassign [toCanvas $w [lindex $p 0] [lindex $p 4]] px py
        set d [expr {($px - $x) ** 2 + ($py - $y) ** 2}]
        if {$d <= $bestD} {
            set best $i
            set bestD $d
        }
        incr i
    }
    return $best
}

# Colour and opacity {r g b a} of the function at u (linear between points).
proc ::pvr::gui::tfeditor::evaluate {w u} {
    variable state
    set pts $state($w,points)
    if {$u <= [lindex $pts 0 0]} {
        return [lrange [lindex $pts 0] 1 4]
    }
    foreach p $pts {
        if {[lindex $p 0] >= $u} {
            lassign $prev u0 r0 g0 b0 a0
            lassign $p u1 r1 g1 b1 a1
            set t [expr {$u1 > $u0 ? ($u - $u0) / ($u1 - $u0) : 1.0}]
            set out {}
            foreach v0 [list $r0 $g0 $b0 $a0] v1 [list $r1 $g1 $b1 $a1] {
                lappend out [expr {$v0 + $t * ($v1 - $v0)}]
            }
            return $out
        }
        set prev $p
    }
    return [lrange [lindex $pts end] 1 4]
}

proc ::pvr::gui::tfeditor::hexColour {r g b} {
    set c {}
    foreach v [list $r $g $b] {
        lappend c [expr {int(round([clamp $v] * 255))}]
    }
    return [format #%02x%02x%02x {*}$c]
}

# ---- Drawing ----

proc ::pvr::gui::tfeditor::redraw {w} {
    variable state
    variable radius
    variable strip
    if {![winfo exists $w] || ![info exists state($w,points)]} {
        return
    }
    $w delete all
    lassign [box $w] x0 y0 x1 y1
    lassign $state($w,range) lo hi

    # Step 1: the background, the histogram in log scale where known (each
    # bin's height is log(1 + fraction * 1e4) of the tallest's), otherwise a
    # grey ramp.
    if {$state($w,hist) ne {}} {
        lassign $state($w,hist) edges fractions
        set peak 0.0
        foreach f $fractions {
            set peak [expr {max($peak, log(1 + $f * 1e4))}]
        }
        set i 0
        foreach f $fractions {
            set ua [expr {([lindex $edges $i] - $lo) / ($hi - $lo)}]
            set ub [expr {([lindex $edges [expr {$i + 1}]] - $lo) / ($hi - $lo)}]
            incr i
            if {$ub <= 0 || $ua >= 1 || $peak <= 0} {
                continue
            }
            set xa [lindex [toCanvas $w [clamp $ua] 0] 0]
            set xb [lindex [toCanvas $w [clamp $ub] 0] 0]
            set h [expr {log(1 + $f * 1e4) / $peak}]
            $w create rectangle $xa $y1 $xb [expr {$y1 - $h * ($y1 - $y0)}] \
                -fill #d9d9d9 -outline #bdbdbd -tags histogram
        }
    } else {
        set n 32
        for {set i 0} {$i < $n} {incr i} {
            set g [expr {int(245 - 40.0 * $i / $n)}]
            set xa [expr {$x0 + ($x1 - $x0) * $i / double($n)}]
            set xb [expr {$x0 + ($x1 - $x0) * ($i + 1) / double($n)}]
            $w create rectangle $xa $y0 $xb $y1 -fill [format #%02x%02x%02x $g $g $g] -outline "" -tags ramp
        }
    }
    $w create rectangle $x0 $y0 $x1 $y1 -outline #808080

    # Step 2: the colour strip below the plot.
    set sy0 [expr {$y1 + 4}]
    set sy1 [expr {$sy0 + $strip}]
    set n [expr {max(1, int($x1 - $x0) / 3)}]
    for {set i 0} {$i < $n} {incr i} {
        set u [expr {($i + 0.5) / $n}]
        lassign [evaluate $w $u] r g b a
        set xa [expr {$x0 + ($x1 - $x0) * $i / double($n)}]
        set xb [expr {$x0 + ($x1 - $x0) * ($i + 1) / double($n)}]
        $w create rectangle $xa $sy0 $xb $sy1 -fill [hexColour $r $g $b] -outline "" -tags strip
    }

    # Step 3: the opacity curve and the points, each filled with its colour.
    set coords {}
    foreach p $state($w,points) {
        lappend coords {*}[toCanvas $w [lindex $p 0] [lindex $p 4]]
    }
    $w create line {*}$coords -fill black -width 2 -tags curve
    set i 0
    foreach p $state($w,points) {
        lassign $p u r g b a
        lassign [toCanvas $w $u $a] x y
        $w create oval [expr {$x - $radius}] [expr {$y - $radius}] [expr {$x + $radius}] [expr {$y + $radius}] \
            -fill [hexColour $r $g $b] -outline [expr {$i == $state($w,drag) ? "red" : "black"}] \
            -width 2 -tags [list point point$i]
        incr i
    }

    # Step 4: the range at both ends.
    $w create text [expr {$x0 + 2}] [expr {$y0 + 2}] -anchor nw -font TkSmallCaptionFont -text [format %g $lo]
    $w create text [expr {$x1 - 2}] [expr {$y0 + 2}] -anchor ne -font TkSmallCaptionFont -text [format %g $hi]
}

# ---- Interaction ----

proc ::pvr::gui::tfeditor::changed {w} {
    variable state
    if {$state($w,command) ne ""} {
        uplevel #0 [linsert $state($w,command) end [points $w]]
    }
}

# Press: grab the point under the pointer, or add one there.
proc ::pvr::gui::tfeditor::press {w x y} {
    variable state
    set i [hit $w $x $y]
    if {$i < 0} {
        lassign [fromCanvas $w $x $y] u a
        lassign [evaluate $w $u] r g b
        set pts [lsort -real -index 0 [linsert $state($w,points) end [list $u $r $g $b $a]]]
        set state($w,points) $pts
        set i [lsearch -exact -index 0 -real $pts $u]
        set state($w,drag) $i
        redraw $w
        changed $w
        return
    }
    set state($w,drag) $i
    redraw $w
}

# Motion: move the grabbed point, keeping it between its neighbours.
proc ::pvr::gui::tfeditor::motion {w x y} {
    variable state
    set i $state($w,drag)
    if {$i < 0} {
        return
    }
    lassign [fromCanvas $w $x $y] u a
    set pts $state($w,points)
    set lo [expr {$i > 0 ? [lindex $pts [expr {$i - 1}] 0] : 0.0}]
    set hi [expr {$i < [llength $pts] - 1 ? [lindex $pts [expr {$i + 1}] 0] : 1.0}]
    lset pts $i 0 [clamp $u $lo $hi]
    lset pts $i 4 $a
    set state($w,points) $pts
    redraw $w
    changed $w
}

proc ::pvr::gui::tfeditor::release {w} {
    variable state
    set state($w,drag) -1
    redraw $w
}

# Right-click: remove the point under the pointer (two always stay).
proc ::pvr::gui::tfeditor::remove {w x y} {
    variable state
    set i [hit $w $x $y]
    if {$i < 0 || [llength $state($w,points)] <= 2} {
        return
    }
    set state($w,points) [lreplace $state($w,points) $i $i]
    set state($w,drag) -1
    redraw $w
    changed $w
}

# Double-click: pick the point's colour.
proc ::pvr::gui::tfeditor::chooseColour {w x y} {
    variable state
    set i [hit $w $x $y]
    if {$i < 0} {
        return
    }
    lassign [lindex $state($w,points) $i] u r g b a
    set c [tk_chooseColor -parent $w -initialcolor [hexColour $r $g $b] -title "Colour of the point"]
    if {$c eq ""} {
        return
    }
    lassign [winfo rgb $w $c] R G B
    lset state($w,points) $i [list $u [expr {$R / 65535.0}] [expr {$G / 65535.0}] [expr {$B / 65535.0}] $a]
    set state($w,drag) -1
    redraw $w
    changed $w
}
