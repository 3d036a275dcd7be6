# session.tcl -- one pvrsh session of bench/scale (run.sh starts pvrd and
# drops the page cache before it): time to the first frame, its phases,
# then the frame rate of the frames after it.
#
#   pvrsh -nogui session.tcl -host HOST:PORT -pvrd PID -dataset NAME -csv FILE
#         ?-kind pvrsh? ?-cache cold|warm? ?-ranks 8? ?-size 512? ?-settings {-tf ... -shading 1 ...}?
#         ?-frames 20? ?-readfile SECONDS? ?-voxels N?
#         ?-series STEPS? ?-cachemem MB?
#
# Static (-series 0): `open`, `set -dataset ...`, `render frame` (the first
# frame: the job reads and preprocesses its bricks), then `render rotate
# 0,0,1 0,F-1:F` (F = -frames) at the same data.
# Series (-series STEPS, the dataset's number of steps): the same first
# frame (step 0), `set -cachemem MB` before it when -cachemem is given,
# then `render time 1,STEPS-1` through the remaining steps, and
# `performance cache` printed after it.
# Appends one row to FILE in run.sh's columns (bench/scale/README.md):
# wall_s is `open` to the first frame's arrival (pvrd's mpirun launch, the
# job's start, the dataset load and the frame); start is `open` alone; the
# phases are the first frame's (max over ranks, as the collector reports
# them); fps is frames over the last frame's arrival; rss from VmHWM of
# every pvr-node under pvrd PID, read before `close`, in pid order;
# cpu_s_frame is their CPU time (all threads, summed over the ranks) from
# the first frame's arrival to the last's, over the frames after the first.
set defaults {-host "" -pvrd 0 -dataset "" -csv "" -kind pvrsh -cache warm -ranks 8 -size 512 -settings ""
              -frames 20 -readfile "" -voxels 0 -series 0 -cachemem ""}
source [file join [file dirname [info script]] .. lib options.tcl]
benchOptions session.tcl $defaults $argv
set ::pvr::progress 0
set phases $::pvr::phases

# readProc: the text of /proc/PID/FILE, or "" when the process is gone.
proc readProc {pid file} {
    if {[catch {
        set f [open /proc/$pid/$file]
        set text [read $f]
        close $f
    }]} { return "" }
    return $text
}

# pvrNodePids: every pvr-node descending from pid `root`, in pid order
# (ranks start in rank order).
proc pvrNodePids {root} {
    set parent [dict create]
    set name [dict create]
    foreach dir [glob -nocomplain -directory /proc {[0-9]*}] {
        set pid [file tail $dir]
        if {[set stat [readProc $pid stat]] eq ""} continue
        # The command name is in parentheses and may hold spaces.
        set close [string last ")" $stat]
        dict set name $pid [string range $stat [expr {[string first "(" $stat] + 1}] [expr {$close - 1}]]
        dict set parent $pid [lindex [string range $stat [expr {$close + 2}] end] 1]
    }
    set pids {}
    foreach pid [lsort -integer [dict keys $name]] {
        if {[dict get $name $pid] ne "pvr-node"} continue
        for {set p $pid} {$p > 1 && $p != $root} {set p [dict get $parent $p]} {
            if {![dict exists $parent $p]} break
        }
        if {$p == $root} { lappend pids $pid }
    }
    return $pids
}

# pvrNodePeaks: the peak RSS (MB) of each of `pids`.
proc pvrNodePeaks {pids} {
    set peaks {}
    foreach pid $pids {
        if {[regexp {VmHWM:\s+(\d+) kB} [readProc $pid status] -> kb]} {
            lappend peaks [format %.1f [expr {$kb / 1024.0}]]
        }
    }
    return $peaks
}

# pvrNodeCpu: the CPU seconds (user + system, every thread) `pids` have
# used so far. Summed over the ranks it is the work a frame costs, which
# on a machine shared with other jobs varies far less than its wall time.
proc pvrNodeCpu {pids} {
    set ticks 0
    foreach pid $pids {
        if {[set stat [readProc $pid stat]] eq ""} continue
        set fields [string range $stat [expr {[string last ")" $stat] + 2}] end]
        incr ticks [expr {[lindex $fields 11] + [lindex $fields 12]}]
    }
    return [expr {$ticks / double($::clockTicks)}]
}
set clockTicks [exec getconf CLK_TCK]

set t0 [clock microseconds]
pvr_session :s
:s open $opt(-host) -ranks $opt(-ranks) -timeout 600
set opened [clock microseconds]
set settings [list -dataset $opt(-dataset) -imagesz $opt(-size),$opt(-size) {*}$opt(-settings)]
if {$opt(-cachemem) ne ""} { lappend settings -cachemem $opt(-cachemem) }
:s set {*}$settings
:s render frame
:s wait -timeout 3600
set first [lindex [:s timing] 0]
set firstAt [clock microseconds]
set pids [pvrNodePids $opt(-pvrd)]
set cpuBefore [pvrNodeCpu $pids]

# The frames after the first.
if {$opt(-series)} {
    :s render time 1,[expr {$opt(-series) - 1}]
    set frames [expr {$opt(-series) - 1}]
} else {
    set frames $opt(-frames)
    :s render rotate 0,0,1 0,[expr {$frames - 1}]:$frames
}
:s wait -timeout 3600
set records [:s timing]
set cpuPerFrame [expr {([pvrNodeCpu $pids] - $cpuBefore) / $frames}]
set fps [expr {$frames / [dict get [lindex $records end] arrival]}]
# Where a later frame's time goes: each phase's mean over the frames after
# the first (for a series, the per-step cost of reading and preprocessing
# beside the render's), in the log beside the first frame's.
set later [lmap p $phases {
    set sum 0.0
    foreach r $records { set sum [expr {$sum + [dict get $r $p]}] }
    format "%s %.3f" $p [expr {$sum / max(1, [llength $records])}]
}]
puts "$opt(-kind) mean per frame after the first: [join $later " "]"
if {$opt(-series) && ![catch {:s performance cache} cache]} {
    puts "$opt(-kind) cache after `render time`: $cache"
    # What reading ahead cost per frame, summed over the ranks: the part of
    # cpu_s_frame the background threads took (read_ahead_cpu_s).
    set aheadCpu 0.0
    set aheadWall 0.0
    foreach r [dict get $cache ranks] {
        if {[dict exists $r read_ahead_cpu_s]} { set aheadCpu [expr {$aheadCpu + [dict get $r read_ahead_cpu_s]}] }
        set aheadWall [expr {$aheadWall + [dict get $r read_ahead_s]}]
    }
    puts [format "%s read-ahead per frame over the ranks: %.4f CPU s, %.4f s wall" \
              $opt(-kind) [expr {$aheadCpu / $frames}] [expr {$aheadWall / $frames}]]
}
set peaks [pvrNodePeaks $pids]
:s close

set wall [expr {($firstAt - $t0) * 1e-6}]
set row [list $opt(-kind) $opt(-ranks) $opt(-cache) $opt(-voxels) [format %.4f $wall] $opt(-readfile) \
             [format %.4f [expr {($opened - $t0) * 1e-6}]]]
foreach p $phases { lappend row [format %.4f [dict get $first $p]] }
lappend row "" $frames [format %.3f $fps]
set rssMax [expr {[llength $peaks] ? [tcl::mathfunc::max {*}$peaks] : ""}]
lappend row $rssMax [join $peaks " "] [format %.4f $cpuPerFrame]
set f [open $opt(-csv) a]
puts $f [join $row ,]
close $f
puts [format "%-15s %d ranks %-4s first frame %.3f s (open %.3f s; %s), then %d frames at %.2f fps, %.3f CPU s per frame over the ranks; peak RSS MB %s" \
      $opt(-kind) $opt(-ranks) $opt(-cache) $wall [expr {($opened - $t0) * 1e-6}] \
      [join [lmap p $phases {format "%s %.3f" $p [dict get $first $p]}] " "] $frames $fps $cpuPerFrame $peaks]
