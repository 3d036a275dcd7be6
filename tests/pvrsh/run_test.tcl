# run_test.tcl FILE.test: sources one tcltest file and exits 1 if any of its
# tests failed (tcltest alone exits 0), so ctest sees the failure.
package require tcltest 2
set file [lindex $argv 0]
::tcltest::configure -verbose {body error}
set failed 0
proc ::tcltest::cleanupTestsHook {} {
    variable numTests
    set ::failed [expr {$numTests(Failed) > 0}]
}
if {[catch {source $file} msg]} {
    puts stderr $msg
    set failed 1
}
# A daemon a failed test file left running is stopped here.
catch {::pvrtest::stopPvrd}
exit $failed
