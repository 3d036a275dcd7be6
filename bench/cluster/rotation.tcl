# rotation.tcl -- one rotation of the CT head through pvrsh, timed per frame
# (bench/cluster/run.sh runs it on h0 of the mini-cluster, once per layout).
#
#   pvrsh -nogui rotation.tcl -host HOST:PORT -tag LAYOUT -csv FILE ?-run 1?
#         ?-ranks 2? ?-frames 36? ?-size 512? ?-preset TF.json? ?-veth NAME?
#
# After one warm-up frame (the job has loaded its bricks), renders
# `render rotate 0,0,1 0,N-1:N` and appends one CSV row per frame to FILE:
# layout, run, frame, the ranks' phases read prep dist rend comp comm send (seconds, as the
# collector reports them with the frame) and arrival (seconds from the
# request to the frame). Prints one summary line: seconds per frame (the
# last arrival over N) and the mean of each phase, and with -veth the bytes
# per frame through that veth during the rotation (the mini-cluster's hosts
# share the machine's /sys, so its counters are readable from h0).
set defaults {-host "" -tag "" -run 1 -csv "" -ranks 2 -frames 36 -size 512 -preset "" -veth ""
              -dataset ct_head_cranium/ct_head_cranium.json}
source [file join [file dirname [info script]] .. lib options.tcl]
benchOptions rotation.tcl $defaults $argv
set ::pvr::progress 0
set phases $::pvr::phases

pvr_session :bench
:bench open $opt(-host) -ranks $opt(-ranks) -timeout 60
set settings [list -dataset $opt(-dataset) -imagesz $opt(-size),$opt(-size)]
if {$opt(-preset) ne ""} {
    lappend settings -tfpreset $opt(-preset)
}
:bench set {*}$settings
:bench render frame
:bench wait -timeout 120

# vethBytes: bytes in and out of the veth -veth names so far (0 without).
proc vethBytes {} {
    if {$::opt(-veth) eq ""} { return 0 }
    set total 0
    foreach way {rx_bytes tx_bytes} {
        set f [open /sys/class/net/$::opt(-veth)/statistics/$way]
        incr total [string trim [read $f]]
        close $f
    }
    return $total
}

set n $opt(-frames)
set bytesBefore [vethBytes]
:bench render rotate 0,0,1 0,[expr {$n - 1}]:$n
:bench wait -timeout 600
set records [:bench timing]
set bytesPerFrame [expr {([vethBytes] - $bytesBefore) / $n}]
:bench close

set f [open $opt(-csv) a]
foreach p $phases { dict set sum $p 0.0 }
foreach r $records {
    puts $f [join [list $opt(-tag) $opt(-run) [dict get $r frame] {*}[lmap p [concat $phases arrival] {dict get $r $p}]] ,]
    foreach p $phases { dict set sum $p [expr {[dict get $sum $p] + [dict get $r $p]}] }
}
close $f
set perFrame [expr {[dict get [lindex $records end] arrival] / $n}]
puts [format "%-14s run %d  %3d frames  %.4f s/frame  %s  %s bytes/frame %d" $opt(-tag) $opt(-run) $n $perFrame \
      [join [lmap p $phases {format "%s %.4f" $p [expr {[dict get $sum $p] / $n}]}] "  "] \
      [expr {$opt(-veth) eq "" ? "-" : $opt(-veth)}] $bytesPerFrame]
