# Options of the Tcl bench scripts run by pvrsh: `-name value` pairs over
# a dict of defaults.
#
# benchOptions SCRIPT DEFAULTS ARGV --
#   Sets the caller's array opt to DEFAULTS merged with ARGV; an option not
#   in DEFAULTS prints the known ones and exits 2.
proc benchOptions {script defaults argv} {
    upvar 1 opt opt
    set unknown [lmap k [dict keys $argv] {expr {[dict exists $defaults $k] ? [continue] : $k}}]
    if {[llength $unknown]} {
        puts stderr "$script: unknown options $unknown (known: [dict keys $defaults])"
        exit 2
    }
    array set opt [dict merge $defaults $argv]
}
