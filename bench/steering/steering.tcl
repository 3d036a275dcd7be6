# The steering example's cost (docs/steering.md): a real pvrd and a job of
# RANKS ranks run the Gray-Scott computation on an N^3 grid and render
# W x W frames of v. Three timings, wall clock at the client:
#   step   seconds per simulation step: `render steps S -every S` (one frame)
#          minus one frame at a fixed step, over S
#   frame  seconds per frame at a fixed step: a rotation of F frames
#   both   seconds per frame with one step before each: `render steps F`
#          (the step, the brick rebuilt: value range, macrocells, classification)
# and the mean of the frames' own timings (preprocess, render, composite).
# The transfer function leaves v below 0.02 clear: diffusion spreads tiny
# values of v over the whole grid within 64 steps, which would otherwise
# leave no empty space to skip.
#
#   TCLLIBPATH=build/lib tclsh8.6 bench/steering/steering.tcl PVRD PVR_NODE ?N? ?RANKS? ?W?
# (defaults: 128 2 512)
package require pvr

lassign $argv pvrd node n ranks width
if {$node eq ""} { error "usage: steering.tcl PVRD PVR_NODE ?N? ?RANKS? ?W?" }
if {$n eq ""} { set n 128 }
if {$ranks eq ""} { set ranks 2 }
if {$width eq ""} { set width 512 }
set S 50
set F 20

set data [file join [pwd] steering-bench-data]
file mkdir $data
set server [open |[list $pvrd --listen 127.0.0.1:0 --data-dir $data --node $node --max-ranks $ranks 2>@stderr] r]
gets $server line
regexp {listening on 127.0.0.1:(\d+)} $line -> port

proc seconds {script} {
    set t0 [clock microseconds]
    uplevel 1 $script
    :b wait -timeout 3600
    expr {([clock microseconds] - $t0) / 1e6}
}
# Mean of KEY over the latest sequence's frame timings.
proc mean {key} {
    set sum 0
    set k 0
    foreach t [:b timing] { set sum [expr {$sum + [dict get $t $key]}]; incr k }
    expr {$sum / $k}
}

pvr_session :b
:b open 127.0.0.1:$port -ranks $ranks
:b set -computation gray-scott,$n,$n,$n -imagesz $width,$width \
    -tf {{0 0 0 0 0} {0.02 0 0 0 0} {0.1 0.2 0.5 1 0.2} {0.3 1 0.9 0.4 0.9}}
:b wait
seconds { :b render frame }  ;# warm: distribution, first classification

set frame [expr {[seconds { :b render rotate 0,0,1 0,[expr {$F - 1}]:$F }] / $F}]
set frameRender [mean rend]
set frameComposite [mean comp]
set steps [seconds { :b render steps $S -every $S }]
set step [expr {($steps - $frame) / $S}]
set both [expr {[seconds { :b render steps $F }] / $F}]
set bothPreprocess [mean prep]
set bothRender [mean rend]

puts [format "gray-scott %d^3 on %d ranks, %dx%d frames" $n $ranks $width $width]
puts [format "  step                          %8.4f s   (%d steps, one frame)" $step $S]
puts [format "  frame at a fixed step         %8.4f s   (render %.4f, composite %.4f)" $frame $frameRender $frameComposite]
puts [format "  frame with one step before it %8.4f s   (render %.4f, preprocess %.4f: value range, macrocells, classification)" \
          $both $bothRender $bothPreprocess]
rename :b {}
catch {exec kill [pid $server]}
catch {close $server}
file delete -force $data
