# stat.tcl -- the per-frame performance graph of paper 003 (Figure 5 sources
# "stat.tcl" to draw "a small performance graph" from the image callback).
#
# One stacked bar per frame on a Tk canvas, split into the five phases the
# server reports for every frame (the timing dict of `:s image callback`):
#   dist  distribute the view to the rendering clusters
#   rend  ray casting
#   comp  compositing
#   comm  collector: RGB conversion and compression
#   send  sending the frame to pvrsh
# A short black tick on each bar marks `arrival` when the dict has it: the
# time from the request to the frame in pvrsh for a single frame, from the
# previous frame for the frames of a sequence (the GUI fills it in so). The
# gap between the top of the bar and the tick is what the phases do not
# account for (queueing, decoding, the network). Bars are labelled with a
# running count of frames received; the server's frame number restarts at 0
# with every request.
#
# Usage:
#   canvas .c.c; pack .c.c
#   ::pvr::gui::stat::attach .c.c          ;# once
#   ::pvr::gui::stat::add .c.c 17 $timing  ;# per frame
#   ::pvr::gui::stat::clear .c.c
# Figure 5's `:brain image callback imgCallback` works as written: the global
# imgCallback below feeds the canvas .c.c when it exists.

package require pvr

namespace eval ::pvr::gui::stat {
    # Phases in stacking order (bottom first): package pvr's list; their colours.
    variable phases $::pvr::phases
    variable colours {read #969696 prep #fdd0a2 dist #8c6bb1 rend #2b8cbe comp #f16913 comm #41ab5d send #d7301f}
    # Per canvas: the frames shown, {frame timingDict count} each, oldest
    # first; count numbers the frames received since attach or clear.
    variable frames
    array set frames {}
    variable counts
    array set counts {}
    # The most frames a graph keeps; older ones scroll off to the left.
    variable maxFrames 60
}

# ::pvr::gui::stat::attach --
#   Prepares canvas `w` for the graph and redraws it when resized.
# Results: `w`.
# Side effects: binds <Configure> on the canvas.
proc ::pvr::gui::stat::attach {w} {
    variable frames
    variable counts
    set frames($w) {}
    set counts($w) 0
    if {[$w cget -width] < 100} {
        $w configure -width 420 -height 180
    }
    $w configure -background white -highlightthickness 0
    bind $w <Configure> [list ::pvr::gui::stat::redraw $w]
    bind $w <Destroy> [list ::pvr::gui::stat::forget $w]
    redraw $w
    return $w
}

proc ::pvr::gui::stat::forget {w} {
    variable frames
    variable counts
    unset -nocomplain frames($w) counts($w)
}

# ::pvr::gui::stat::add --
#   Appends frame `frame` with `timing` (dict: read prep dist rend comp comm send, in
#   seconds; arrival optional) and redraws.
# Side effects: drops the oldest frame beyond maxFrames.
proc ::pvr::gui::stat::add {w frame timing} {
    variable frames
    variable counts
    variable maxFrames
    if {![info exists frames($w)]} {
        attach $w
    }
    lappend frames($w) [list $frame $timing [incr counts($w)]]
    if {[llength $frames($w)] > $maxFrames} {
        set frames($w) [lrange $frames($w) end-[expr {$maxFrames - 1}] end]
    }
    redraw $w
}

proc ::pvr::gui::stat::clear {w} {
    variable frames
    variable counts
    set frames($w) {}
    set counts($w) 0
    redraw $w
}

# ::pvr::gui::stat::frames --
#   The frames shown on `w`, {frame timing count} each (tests read it).
proc ::pvr::gui::stat::frames {w} {
    variable frames
    if {![info exists frames($w)]} {
        return {}
    }
    return $frames($w)
}

# ::pvr::gui::stat::phaseValue --
#   One phase's seconds from a timing dict; missing or non-numeric is 0.
proc ::pvr::gui::stat::phaseValue {timing key} {
    if {[dict exists $timing $key] && [string is double -strict [dict get $timing $key]]} {
        return [dict get $timing $key]
    }
    return 0.0
}

# ::pvr::gui::stat::niceStep --
#   A round axis step (1, 2 or 5 times a power of ten) giving about 4 ticks
#   up to `top`.
proc ::pvr::gui::stat::niceStep {top} {
    set raw [expr {$top / 4.0}]
    set p [expr {pow(10, floor(log10($raw)))}]
    foreach m {1 2 5 10} {
        if {$m * $p >= $raw} {
            return [expr {$m * $p}]
        }
    }
    return [expr {10 * $p}]
}

# ::pvr::gui::stat::redraw --
#   Draws axes, one stacked bar per frame, arrival ticks, the legend and the
#   mean breakdown of the frames shown.
proc ::pvr::gui::stat::redraw {w} {
    variable frames
    variable phases
    variable colours
    if {![winfo exists $w]} {
        return
    }
    $w delete all
    set width [winfo width $w]
    set height [winfo height $w]
    if {$width <= 1} {
        set width [$w cget -width]
        set height [$w cget -height]
    }
    # Plot area: room on the left for the seconds axis, at the bottom for
    # frame numbers, at the top for the legend.
    set x0 46
    set x1 [expr {$width - 8}]
    set y0 [expr {$height - 20}]
    set y1 30
    set list [expr {[info exists frames($w)] ? $frames($w) : {}}]

    # Step 1: the scale, from the tallest bar or arrival.
    set top 0.0
    set sums [dict create]
    foreach p $phases {
        dict set sums $p 0.0
    }
    foreach item $list {
        set t [lindex $item 1]
        set total 0.0
        foreach p $phases {
            set v [phaseValue $t $p]
            set total [expr {$total + $v}]
            dict set sums $p [expr {[dict get $sums $p] + $v}]
        }
        set top [expr {max($top, $total, [phaseValue $t arrival])}]
    }
    if {$top <= 0} {
        set top 0.1
    }
    set step [niceStep $top]
    set top [expr {ceil($top / $step) * $step}]
    set scale [expr {($y0 - $y1) / $top}]

    # Step 2: axes and grid lines in seconds (milliseconds below 1 s).
    $w create line $x0 $y1 $x0 $y0 $x1 $y0 -fill black
    for {set v 0.0} {$v <= $top + 1e-12} {set v [expr {$v + $step}]} {
        set y [expr {$y0 - $v * $scale}]
        $w create line $x0 $y $x1 $y -fill #e0e0e0 -tags grid
        set label [expr {$top < 1 ? [format %g [expr {round($v * 1e4) / 10.0}]] : [format %g $v]}]
        $w create text [expr {$x0 - 4}] $y -text $label -anchor e -font TkSmallCaptionFont
    }
    $w create text 4 [expr {$y1 - 12}] -anchor w -font TkSmallCaptionFont \
        -text [expr {$top < 1 ? "ms" : "s"}]
    $w lower grid

    # Step 3: one stacked bar per frame.
    set n [llength $list]
    set slots [expr {max($n, 10)}]
    set slot [expr {double($x1 - $x0 - 4) / $slots}]
    set barWidth [expr {max(1.0, $slot * 0.8)}]
    set i 0
    foreach item $list {
        lassign $item frame t count
        set left [expr {$x0 + 3 + $i * $slot}]
        set right [expr {$left + $barWidth}]
        set y $y0
        foreach p $phases {
            set h [expr {[phaseValue $t $p] * $scale}]
            if {$h > 0} {
                $w create rectangle $left $y $right [expr {$y - $h}] \
                    -fill [dict get $colours $p] -outline "" -tags [list bar count$count $p]
                set y [expr {$y - $h}]
            }
        }
        if {[dict exists $t arrival]} {
            set ya [expr {$y0 - [phaseValue $t arrival] * $scale}]
            $w create line [expr {$left - 1}] $ya [expr {$right + 1}] $ya -width 2 -fill black -tags arrival
        }
        # Label every frame when they fit, otherwise every fifth.
        if {$slot >= 18 || $count % 5 == 0} {
            $w create text [expr {($left + $right) / 2}] [expr {$y0 + 9}] \
                -text $count -font TkSmallCaptionFont
        }
        incr i
    }

    # Step 4: legend with each phase's mean (ms) over the frames shown.
    set id [$w create text $x0 11 -anchor w -font TkSmallCaptionFont -text "mean ms:"]
    set x [expr {[lindex [$w bbox $id] 2] + 6}]
    foreach p $phases {
        set mean [expr {$n > 0 ? [dict get $sums $p] / $n : 0.0}]
        $w create rectangle $x 6 [expr {$x + 10}] 16 -fill [dict get $colours $p] -outline ""
        set id [$w create text [expr {$x + 13}] 11 -anchor w -font TkSmallCaptionFont \
            -text [format "%s %.1f" $p [expr {$mean * 1e3}]] -tags legend]
        set x [expr {[lindex [$w bbox $id] 2] + 8}]
    }
    $w create line $x 11 [expr {$x + 10}] 11 -width 2 -fill black
    $w create text [expr {$x + 13}] 11 -anchor w -font TkSmallCaptionFont -text arrival
}

# imgCallback --
#   Figure 5 of paper 003: `:brain image callback imgCallback` after
#   `source stat.tcl` draws each frame's times on the canvas .c.c.
if {[info commands ::imgCallback] eq ""} {
    proc ::imgCallback {frame timing} {
        if {[winfo exists .c.c]} {
            ::pvr::gui::stat::add .c.c $frame $timing
        }
    }
}
