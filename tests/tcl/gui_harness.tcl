# gui_harness.tcl -- what the GUI test scripts share (tests/tcl/*_test.tcl):
# `check` counts failures in ::failures, `waitFor` runs the event loop
# until a condition holds. Each script has its own `finish`, which reports
# and exits with the failures counted.

set failures 0

# check: `condition` is an expression evaluated in the caller.
proc check {name condition {detail ""}} {
    if {[uplevel 1 [list expr $condition]]} {
        puts "ok   $name"
    } else {
        puts "FAIL $name $detail"
        incr ::failures
    }
}

# waitFor: runs the event loop until `condition` (evaluated globally) holds,
# or `seconds` pass. Results: 1 when it held.
proc waitFor {condition seconds} {
    set deadline [expr {[clock milliseconds] + int($seconds * 1000)}]
    while {![uplevel #0 [list expr $condition]]} {
        if {[clock milliseconds] > $deadline} {
            return 0
        }
        after 20 {set ::tick 1}
        vwait ::tick
    }
    return 1
}
