# One session renders a rotation and reports what the cluster tests check
# (run with pvrsh -nogui on h0):
#
#   rotation.tcl HOST:PORT RANKS DATASET DIR FRAMES ?OPEN-OPTION ...?
#
# Frames go to DIR/r_00000.png, ... Prints on stdout
#   order F F ...   the frame numbers in the order their callbacks ran
#   hosts H H ...   the server's status entry `hosts` (every rank's host)
#   bytes N         the bytes that went between compute hosts during the
#                   rotation (`$PVR_CLUSTER_SH compute-bytes` before and after)
# Any error (open, a server error during wait) exits non-zero with its
# message and -errorcode on stderr.
set openOptions [lassign $argv server ranks dataset dir frames]

set order {}
proc arrived {frame timing} { lappend ::order $frame }

pvr_session :r
:r image dir $dir
:r image callback arrived
:r open $server -ranks $ranks -timeout 60 {*}$openOptions
:r set -dataset $dataset -imagesz 96,96 -background 0,0,0 \
    -tf {0 0 0 0 0  0.3 0.2 0.4 1 0.05  0.6 1 0.8 0.2 0.3  1 1 1 1 0.8}
set before [exec $env(PVR_CLUSTER_SH) compute-bytes]
:r render rotate 0,0,1 0,[expr {$frames - 1}]:$frames
:r wait -timeout 60
set bytes [expr {[exec $env(PVR_CLUSTER_SH) compute-bytes] - $before}]
set remote [dict get [:r list status] remote]
puts "order $order"
puts "bytes $bytes"
puts "hosts [expr {[dict exists $remote hosts] ? [dict get $remote hosts] : "(no hosts entry)"}]"
:r close
