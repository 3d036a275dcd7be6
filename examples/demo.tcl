# The demo: a session with 4 ranks renders a 36-frame shaded rotation of a
# dataset (the CT head with the bone preset when the catalog has it, else
# the first dataset) and writes the frames into out/ (PNG, plus
# out/demo.mp4 when ffmpeg is installed). pvrsh prints progress and, at the
# end, the per-frame timing table. Paths are the script's own: it runs
# from any directory.
#
#   pvrsh examples/demo.tcl ?HOST:PORT? ?OUTDIR?
#
# HOST:PORT: first argument, else $PVR_SERVER, else 127.0.0.1:7350.
set host [expr {[llength $argv] > 0 ? [lindex $argv 0] :
                [info exists env(PVR_SERVER)] ? $env(PVR_SERVER) : "127.0.0.1:7350"}]
set out [expr {[llength $argv] > 1 ? [lindex $argv 1] : "out"}]
file mkdir $out
set here [file dirname [file normalize [info script]]]

pvr_session :demo
:demo open $host -ranks 4
set catalog [:demo list datasets]
if {![llength $catalog]} { error "the server's catalog is empty" }
set dataset [lindex $catalog 0]
foreach name $catalog {
    if {[string match -nocase *ct_head* $name]} { set dataset $name; break }
}
puts stderr "demo: $dataset on $host, 4 ranks, 36 frames into $out/"

# Shaded, with the lighting of examples/scenes/ct_head_bone.json, so the
# frames look as pvr-render's image of that scene does.
:demo set -dataset $dataset -imagesz 512,512 -shading 1 -ambient 0.25 -diffuse 0.75 -specular 0.3 -shininess 24
if {[string match -nocase *ct_head* $dataset]} {
    :demo set -tfpreset [file join $here presets ct_bone.json]
}
:demo image file [file join $out demo.mp4]
:demo render rotate 0,0,1 0,35:36
set frames [:demo wait]
puts stderr "demo: $frames frames written to $out/"
:demo close
