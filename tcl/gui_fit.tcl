# gui_fit.tcl -- the PVR GUI's image view scaled to its window (issue 14,
# point 9): a frame larger than the room the window gives the view is shown
# shrunk, so a 1024x1024 frame never pushes the window past the screen.
#
# Frames arrive in the photo ::pvr::gui::image at full size (saving it or
# comparing pixels sees the frame). The label .view.image shows that photo
# itself when it fits, otherwise ::pvr::gui::fit::shown, a copy subsampled
# by the smallest whole factor that fits (Tk photos scale by whole
# factors). The frame .view does not take its size from the label: it asks
# for the frame's size, capped by the screen, and gets less when the window
# is smaller; its <Configure> refits the view.

namespace eval ::pvr::gui::fit {
    # The subsampling factor in force (1: the frame as it is).
    variable factor 1
    # The photo shown when the factor is above 1.
    variable shown ::pvr::gui::fit::shown
}

# ::pvr::gui::fit::screenBox --
#   The most room the view may ask for: the screen less the controls beside
#   it and the status bar below (and a margin for window decorations).
proc ::pvr::gui::fit::screenBox {} {
    set w [expr {[winfo screenwidth .] - [winfo reqwidth .ctl] - 40}]
    set h [expr {[winfo screenheight .] - [winfo reqheight .bar] - 80}]
    return [list [expr {max(64, $w)}] [expr {max(64, $h)}]]
}

# ::pvr::gui::fit::request --
#   The view asks for the frame's size (capped by the screen); the window
#   grows or shrinks to it unless its size was set (by the user or wm
#   geometry), in which case the view gets what is left.
proc ::pvr::gui::fit::request {} {
    set photo $::pvr::gui::image
    lassign [screenBox] bw bh
    .view configure -width [expr {min([::image width $photo], $bw) + 8}] \
        -height [expr {min([::image height $photo], $bh) + 8}]
}

# ::pvr::gui::fit::room --
#   The room the view has now: its frame's size less the padding, or the
#   screen box before the window is mapped.
proc ::pvr::gui::fit::room {} {
    if {![winfo ismapped .view]} {
        return [screenBox]
    }
    return [list [expr {max(16, [winfo width .view] - 8)}] [expr {max(16, [winfo height .view] - 8)}]]
}

# ::pvr::gui::fit::refit --
#   Shows the frame in the room there is: itself when it fits, else
#   subsampled. Called for each frame and when the view's size changes.
proc ::pvr::gui::fit::refit {} {
    variable factor
    variable shown
    set photo $::pvr::gui::image
    set w [::image width $photo]
    set h [::image height $photo]
    lassign [room] rw rh
    set factor [expr {max(1, int(ceil(double($w) / $rw)), int(ceil(double($h) / $rh)))}]
    if {$factor == 1} {
        .view.image configure -image $photo
        return
    }
    if {$shown ni [::image names]} {
        ::image create photo $shown
    }
    # Blank first: a copy with -subsample keeps the target's old size.
    $shown blank
    $shown configure -width [expr {($w + $factor - 1) / $factor}] -height [expr {($h + $factor - 1) / $factor}]
    $shown copy $photo -subsample $factor $factor
    .view.image configure -image $shown
}

# ::pvr::gui::fit::attach --
#   Places the label in the middle of the view frame and refits on resizes.
proc ::pvr::gui::fit::attach {} {
    grid propagate .view 0
    pack propagate .view 0
    place .view.image -relx 0.5 -rely 0.5 -anchor center
    bind .view <Configure> ::pvr::gui::fit::refit
    request
}
