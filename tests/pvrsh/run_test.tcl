# run_test.tcl FILE.test: sources one tcltest file and exits 1 unless every
# one of its tests ran and passed, so ctest sees a failure (tcltest alone
# exits 0). A skipped test counts as a failure: the files state no
# constraints, and a test that was not run proves nothing.
package require tcltest 2
set file [lindex $argv 0]
::tcltest::configure -verbose {body error}
set failed 0
proc ::tcltest::cleanupTestsHook {} {
    variable numTests
    set ::failed [expr {$numTests(Failed) > 0 || $numTests(Skipped) > 0 || $numTests(Total) == 0}]
}
# With Tk loaded, cleanupTests ends the process itself, with status 0; every
# exit goes through here so that the verdict decides the status.
rename exit ::pvrtest_exit
proc exit {{status 0}} {
    # A daemon a failed test file left running is stopped here.
    catch {::pvrtest::stopPvrd}
    ::pvrtest_exit [expr {$status != 0 || $::failed ? 1 : 0}]
}
if {[catch {source $file} msg]} {
    puts stderr $msg
    set failed 1
}
exit $failed
