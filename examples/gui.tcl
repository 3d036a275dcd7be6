# gui.tcl -- the PVR GUI (paper 003, Figure 13).
#
#   pvrsh examples/gui.tcl ?-host HOST:PORT? ?-ranks N? ?-dataset NAME?
#                          ?-imagesz WxH?
#
# With -host it connects at once (otherwise type the address and press
# Connect; PVR_SERVER sets the default). -dataset picks a catalog entry by
# its name (the file's stem) or file name. The transfer-function editor
# shows the histogram the server counted when it loaded the data.
#
# Drag the image to turn the view about the camera the server reports; the
# arrows turn it by 15 degrees. The transfer-function editor spans the
# data's value range and applies every change at once; "Preset..." loads a
# ParaView preset. "Clusters and groups" sets -cluster/-group and the
# compositing strategy and decomposition, from the names the server
# offers; the second window graphs each frame's times.
package require Tk
if {[catch {package require pvr}]} {
    # Under plain wish: the package from the build tree.
    lappend auto_path [file join [file dirname [info script]] .. build lib]
    package require pvr
}
source [file join [file dirname [file normalize [info script]]] .. tcl gui.tcl]
::pvr::gui::main {*}$argv
