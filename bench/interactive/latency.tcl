# latency.tcl -- request-to-pixels latency of single frames in a Tk window.
#
#   pvrsh latency.tcl -host HOST:PORT ?-frames 50? ?-ranks 2? ?-shading 1?
#                     ?-preset TF.json? ?-size 512? ?-out DIR? ?-tag latency?
#                     ?-interactive 0? ?-reduction 4? ?-edit view? ?-earlyterm A?
#
# A photo in a label on screen receives the frames (`:s image window`). For
# each of -frames single frames of the CT head (after 3 warm-up frames) it
# takes the time of `:s render frame` and two arrival times:
#   photo  when `:s image callback` runs: the pixels are in the photo;
#   shown  when the event loop next goes idle: Tk has redrawn the label
#          (its redisplay was queued before ours), so the pixels are on the
#          window.
# The view turns 7 degrees between frames (`:s set -eye ...` would need the
# bounds; `render rotate 0,0,1 K,K:360` is one frame of the automatic
# camera turned K degrees), so every frame is new pixels; the request is
# still one frame. Writes DIR/TAG.csv (not -name: Tk takes that one) and prints median and p90.
#
# With -edit tf each request is instead a transfer-function edit and a
# frame (`set -tf ...; render frame`): the preset's points (as the server
# resolved them) move by 0 to 40 from request to request, so its transparent end moves
# and every rank classifies its brick again (the clear cells included);
# -edit colour recolours the points alone (the ends stay). The view stays.
#
# With -interactive 1 each request is `render rotate ... -interactive
# -reduction R` (progressive refinement, docs/pvrsh.md): the first pixels
# are its coarse frame's, and request-to-full-quality is its second
# frame's; both are reported. Without it the first pixels are the frame's.

package require Tk

array set opt {-host "" -frames 50 -ranks 2 -shading 1 -preset "" -size 512 -out . -tag latency
               -dataset ct_head_cranium/ct_head_cranium.json -interactive 0 -reduction 4 -edit view
               -earlyterm ""}
foreach {k v} $argv {
    if {![info exists opt($k)]} {
        puts stderr "latency.tcl: unknown option $k"
        exit 2
    }
    set opt($k) $v
}
if {$opt(-edit) ni {view tf colour}} {
    puts stderr "latency.tcl: -edit must be view, tf or colour, got '$opt(-edit)'"
    exit 2
}
set ::pvr::progress 0
set size $opt(-size)

# The window: a photo in a label, as the GUI shows it.
wm title . "PVR latency"
image create photo frame -width $size -height $size
label .l -image frame -borderwidth 0
pack .l
update

pvr_session :bench
:bench image window frame
:bench image callback onFrame
:bench notify onNotify
:bench open $opt(-host) -ranks $opt(-ranks)
set settings [list -dataset $opt(-dataset) -imagesz $size,$size -shading $opt(-shading)]
if {$opt(-preset) ne ""} {
    lappend settings -tfpreset $opt(-preset)
}
if {$opt(-earlyterm) ne ""} {
    lappend settings -earlyterm $opt(-earlyterm)
}
:bench set {*}$settings

# Per request: its start, and per quality (coarse, full) the photo time,
# shown time (microseconds) and timing.
set current {}
proc onFrame {frame timing} {
    set quality [dict get $timing quality]
    dict set ::current $quality photo [clock microseconds]
    dict set ::current $quality timing $timing
    after idle [list shown $quality]
}
proc shown {quality} {
    dict set ::current $quality shown [clock microseconds]
    if {$quality eq "full"} {
        set ::arrived 1
    }
}
proc onNotify {event args} {
    if {$event eq "error"} {
        puts stderr "latency.tcl: [lindex $args 0]"
        exit 1
    }
}

# The session's transfer function (-preset's points as the server resolved
# them, ::tfPoints) moved by `shift` above its first point, or with its
# colours turned by `turn` (0 or 1).
proc editedTf {shift turn} {
    set points {}
    set first 1
    foreach {s r g b a} $::tfPoints {
        if {$turn} {
            lassign [list $b $r $g] r g b
        }
        lappend points [expr {$first ? $s : $s + $shift}] $r $g $b $a
        set first 0
    }
    return $points
}

# one: a single frame at `degrees` (or, with -edit, the k-th edit); returns
# its record.
proc one {degrees} {
    set ::current {}
    set ::arrived 0
    set start [clock microseconds]
    set progressive [expr {$::opt(-interactive) ? [list -interactive -reduction $::opt(-reduction)] : {}}]
    set k [expr {$degrees / 7}]
    if {$::opt(-edit) eq "tf"} {
        :bench set -tf [editedTf [expr {10 * ($k % 5)}] 0]
        :bench render frame {*}$progressive
    } elseif {$::opt(-edit) eq "colour"} {
        :bench set -tf [editedTf 0 [expr {$k % 2}]]
        :bench render frame {*}$progressive
    } elseif {$degrees % 360 == 0} {
        :bench render frame {*}$progressive
    } else {
        :bench render rotate 0,0,1 $degrees,$degrees:360 {*}$progressive
    }
    vwait ::arrived
    # The request is over when `wait` returns (the notify of its end).
    :bench wait -timeout 30
    dict set ::current start $start
    return $::current
}

if {$opt(-edit) ne "view"} {
    # The resolved points exist once the dataset is loaded: a frame first.
    set ::arrived 0
    :bench render frame
    vwait ::arrived
    :bench wait -timeout 30
    set ::tfPoints [dict get [dict get [:bench list status] remote] transfer_function]
}
foreach k {0 1 2} {
    one [expr {$k * 7}]
}
lassign [frame get [expr {$size / 2}] [expr {$size / 2}]] r g b
set records {}
for {set i 0} {$i < $opt(-frames)} {incr i} {
    lappend records [one [expr {($i + 3) * 7}]]
}

# ---- Report ----
proc percentile {values p} {
    set sorted [lsort -real $values]
    set n [llength $sorted]
    # Nearest rank.
    set k [expr {max(0, min($n - 1, int(ceil($p * $n)) - 1))}]
    return [lindex $sorted $k]
}
set photo {}
set shown {}
set firstPhoto {}
set firstShown {}
set overhead {}
set phases $::pvr::phases
set firstOverhead {}
foreach p $phases {
    set sum($p) 0.0
    set firstSum($p) 0.0
}
file mkdir $opt(-out)
set csv [open [file join $opt(-out) $opt(-tag).csv] w]
# The server's phases of the full frame, in $::pvr::phases order, then the
# first pixels' times and the first frame's phases.
puts $csv "frame,request_to_photo_s,request_to_shown_s,[join [lmap p $phases {string cat $p _s}] ,],request_to_first_photo_s,request_to_first_shown_s,[join [lmap p $phases {string cat first_ $p _s}] ,]"
set i 0
foreach rec $records {
    # The full-quality frame, and the first pixels: the coarse frame's
    # when the render is interactive.
    set first [expr {[dict exists $rec coarse] ? "coarse" : "full"}]
    set tp [expr {([dict get $rec full photo] - [dict get $rec start]) / 1e6}]
    set ts [expr {([dict get $rec full shown] - [dict get $rec start]) / 1e6}]
    set fp [expr {([dict get $rec $first photo] - [dict get $rec start]) / 1e6}]
    set fs [expr {([dict get $rec $first shown] - [dict get $rec start]) / 1e6}]
    lappend photo $tp
    lappend shown $ts
    lappend firstPhoto $fp
    lappend firstShown $fs
    dict set rec timing [dict get $rec full timing]
    set server 0.0
    foreach p $phases {
        set server [expr {$server + [dict get [dict get $rec timing] $p]}]
    }
    # What the server's phases do not account for: request and frame on the
    # wire, queueing, zlib decode, the photo update.
    lappend overhead [expr {$tp - $server}]
    set row [list $i [format %.4f $tp] [format %.4f $ts]]
    foreach p $phases {
        set v [dict get [dict get $rec timing] $p]
        set sum($p) [expr {$sum($p) + $v}]
        lappend row [format %.4f $v]
    }
    lappend row [format %.4f $fp] [format %.4f $fs]
    set firstServer 0.0
    foreach p $phases {
        set v [dict get [dict get $rec $first timing] $p]
        set firstSum($p) [expr {$firstSum($p) + $v}]
        set firstServer [expr {$firstServer + $v}]
        lappend row [format %.4f $v]
    }
    lappend firstOverhead [expr {$fp - $firstServer}]
    puts $csv [join $row ,]
    incr i
}
close $csv

set n [llength $records]
set status [:bench list status]
set f [open /proc/loadavg]
set load [lindex [read $f] 0]
close $f
puts "PVR interactive latency: $opt(-dataset), ${size}x${size}, $n frames after 3 warm-up,\
      [dict get $status ranks] ranks, shading $opt(-shading), [exec nproc] cores, load average $load,\
      [expr {$opt(-interactive) ? "interactive (coarse 1/$opt(-reduction) per axis, then full)" : "full frames only"}],\
      [dict get {view "the view turning" tf "the transfer function moving" colour "the colours changing"} $opt(-edit)]"
puts [format "request-to-first-pixels  photo median %.3f s  p90 %.3f s;  shown median %.3f s  p90 %.3f s  (target 0.05 s: %s)" \
          [percentile $firstPhoto 0.5] [percentile $firstPhoto 0.9] [percentile $firstShown 0.5] \
          [percentile $firstShown 0.9] [expr {[percentile $firstShown 0.5] <= 0.05 ? "met" : "missed"}]]
set parts {}
foreach p $phases {
    lappend parts [format "%s %.1f ms" $p [expr {$firstSum($p) / $n * 1e3}]]
}
puts "first frame's server phases, mean: [join $parts {  }]"
puts [format "first frame outside the server's phases (dispatch, wire, decode, photo): median %.1f ms" \
          [expr {[percentile $firstOverhead 0.5] * 1e3}]]
puts "request-to-full-quality (below):"
puts [format "request-to-photo  median %.3f s  p90 %.3f s" [percentile $photo 0.5] [percentile $photo 0.9]]
puts [format "request-to-shown  median %.3f s  p90 %.3f s  (target 0.25 s: %s)" \
          [percentile $shown 0.5] [percentile $shown 0.9] \
          [expr {[percentile $shown 0.5] <= 0.25 ? "met" : "missed"}]]
set parts {}
foreach p $phases {
    lappend parts [format "%s %.1f ms" $p [expr {$sum($p) / $n * 1e3}]]
}
puts "server phases, mean: [join $parts {  }]"
puts [format "outside the server's phases (wire, decode, photo): median %.1f ms" [expr {[percentile $overhead 0.5] * 1e3}]]
puts "centre pixel after warm-up (not background when the head is there): $r $g $b"
:bench close
exit 0
