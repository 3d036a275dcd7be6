# pvrsh's per-frame bookkeeping against the number of frames (issue 15,
# finding 15: a copy of every record per frame made 40000 frames take
# 18.3 s). A fake server (tests/pvrsh/fake_pvrd.tcl) sends one rotation of
# N tiny frames as fast as Tcl writes them; the table gives the seconds
# from `render` to the end of `wait`, and microseconds per frame, which
# stay flat when the bookkeeping is linear.
#
#   TCLLIBPATH=build/lib tclsh8.6 bench/pvrsh/frames_linear.tcl ?N ...?
# (default N: 10000 20000 40000)
package require pvr
source [file join [file dirname [info script]] .. .. tests pvrsh fake_pvrd.tcl]

set counts [expr {$argc > 0 ? $argv : {10000 20000 40000}}]
puts [format "%8s %10s %14s" frames seconds us/frame]
foreach n $counts {
    set port [::fakepvrd::start ready]
    pvr_session :b
    :b open 127.0.0.1:$port
    set t0 [clock microseconds]
    :b render rotate 0,1,0 0,[expr {$n - 1}]:$n
    set got [:b wait -timeout 600]
    set s [expr {([clock microseconds] - $t0) / 1e6}]
    if {$got != $n} { error "expected $n frames, got $got" }
    puts [format "%8d %10.3f %14.1f" $n $s [expr {$s * 1e6 / $n}]]
    rename :b {}
    ::fakepvrd::stop
}
