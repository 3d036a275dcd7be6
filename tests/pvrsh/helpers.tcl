# Helpers shared by the pvr tcltest files: a small raw+JSON volume in a
# temporary data directory, and pvrd started on an ephemeral loopback port.
#
# The environment (set by tests/pvrsh/CMakeLists.txt) names the programs:
# PVRD, PVR_NODE (pvr-node), PVRSH, PVR_RENDER, and PVR_TEST_TMP. A test file
# that needs a program asks ::pvrtest::program for it: a file registered
# without its programs fails instead of skipping its tests.

package require tcltest 2
namespace import ::tcltest::*
package require pvr

namespace eval ::pvrtest {
    variable tmp [file join $::env(PVR_TEST_TMP) [pid]]
    variable pvrd ""        ;# channel of the running pvrd
    variable pvrdPid 0
    variable port 0
}

# ::pvrtest::program VAR: the program the environment variable VAR names;
# an error when it is not set or not executable.
proc ::pvrtest::program {var} {
    if {![info exists ::env($var)]} {
        error "this test needs the program named by \$$var, which is not set (tests/pvrsh/CMakeLists.txt sets it)"
    }
    if {![file executable $::env($var)]} {
        error "\$$var names $::env($var), which is not an executable (build it first)"
    }
    return $::env($var)
}

# ::pvrtest::makeData DIR: writes ball/ball.raw + ball.json, a 32^3 uint8
# sphere whose value falls off from the centre, and a second copy "cube".
proc ::pvrtest::makeData {dir} {
    file mkdir [file join $dir ball]
    set n 32
    set bytes {}
    for {set z 0} {$z < $n} {incr z} {
        for {set y 0} {$y < $n} {incr y} {
            set row {}
            for {set x 0} {$x < $n} {incr x} {
                set r [expr {sqrt(($x-15.5)**2 + ($y-15.5)**2 + ($z-15.5)**2)}]
                lappend row [expr {$r < 12 ? int(255 - $r * 10) : 0}]
            }
            append bytes [binary format c* $row]
        }
    }
    set f [open [file join $dir ball ball.raw] wb]
    puts -nonewline $f $bytes
    close $f
    set f [open [file join $dir ball ball.json] w]
    puts $f {{"dims": [32, 32, 32], "dtype": "uint8", "spacing": [1, 1, 1], "origin": [0, 0, 0], "raw_file": "ball.raw", "endian": "little"}}
    close $f
    return $dir
}

# ::pvrtest::makeSeries DIR N: a time series of N steps beside the ball
# (docs/scene.md, series sidecar): step k is ball/step_K.raw + step_K.json,
# the ball's values times 1 - 0.2 k, listed by ball/ball.series.json at
# times 0, 0.5, 1, ... Returns the catalog name of the series.
proc ::pvrtest::makeSeries {dir n} {
    set ball [file join $dir ball]
    set f [open [file join $ball ball.raw] rb]
    binary scan [read $f] cu* values
    close $f
    set steps {}
    for {set k 0} {$k < $n} {incr k} {
        set scaled [lmap v $values {expr {int($v * (1 - 0.2 * $k))}}]
        set f [open [file join $ball step_$k.raw] wb]
        puts -nonewline $f [binary format c* $scaled]
        close $f
        set f [open [file join $ball step_$k.json] w]
        puts $f [format {{"dims": [32, 32, 32], "dtype": "uint8", "spacing": [1, 1, 1], "origin": [0, 0, 0], "raw_file": "step_%d.raw", "endian": "little"}} $k]
        close $f
        lappend steps [format {{"time": %s, "file": "step_%d.json"}} [expr {0.5 * $k}] $k]
    }
    set f [open [file join $ball ball.series.json] w]
    puts $f "{\"series\": \[[join $steps {, }]\]}"
    close $f
    return ball/ball.series.json
}

# ::pvrtest::startPvrd ?ARGS?: starts pvrd on 127.0.0.1:0 over a fresh data
# directory; returns the port. Stopped by stopPvrd (or at exit).
proc ::pvrtest::startPvrd {args} {
    variable tmp
    variable pvrd
    variable pvrdPid
    variable port
    set data [makeData [file join $tmp data]]
    set cmd [list [program PVRD] --listen 127.0.0.1:0 --data-dir $data --node [program PVR_NODE] {*}$args]
    set pvrd [open |[concat $cmd [list 2>> [file join $tmp pvrd.log]]] r]
    set pvrdPid [pid $pvrd]
    gets $pvrd line
    if {![regexp {pvrd listening on 127.0.0.1:(\d+)} $line -> port]} {
        error "pvrd did not start: $line"
    }
    return $port
}

proc ::pvrtest::stopPvrd {} {
    variable pvrd
    variable pvrdPid
    if {$pvrd eq ""} return
    catch {exec kill -TERM $pvrdPid}
    catch {close $pvrd}
    set pvrd ""
    set pvrdPid 0
}

# ::pvrtest::killPvrd: SIGKILL, as a crash would.
proc ::pvrtest::killPvrd {} {
    variable pvrd
    variable pvrdPid
    catch {exec kill -KILL $pvrdPid}
    catch {close $pvrd}
    set pvrd ""
    set pvrdPid 0
}

# ::pvrtest::near GOT WANT ?TOLERANCE?: 1 when the number lists GOT and WANT
# have the same length and agree element by element within TOLERANCE.
proc ::pvrtest::near {got want {tolerance 1e-9}} {
    if {[llength $got] != [llength $want]} {
        return 0
    }
    foreach a $got b $want {
        if {![string is double -strict $a] || abs($a - $b) > $tolerance} {
            return 0
        }
    }
    return 1
}

# ::pvrtest::maxDiff A B: the largest difference of any 8-bit channel
# between the Tk photo images A and B of one size (needs Tk).
proc ::pvrtest::maxDiff {a b} {
    if {[image width $a] != [image width $b] || [image height $a] != [image height $b]} {
        error "images $a and $b differ in size"
    }
    set worst 0
    for {set y 0} {$y < [image height $a]} {incr y} {
        for {set x 0} {$x < [image width $a]} {incr x} {
            foreach p [$a get $x $y] q [$b get $x $y] {
                set d [expr {abs($p - $q)}]
                if {$d > $worst} { set worst $d }
            }
        }
    }
    return $worst
}

# ::pvrtest::errorcode SCRIPT: the -errorcode of SCRIPT's error, or "ok".
proc ::pvrtest::errorcode {script} {
    if {[catch {uplevel 1 $script} msg opts]} {
        return [dict get $opts -errorcode]
    }
    return ok
}

file mkdir $::pvrtest::tmp
