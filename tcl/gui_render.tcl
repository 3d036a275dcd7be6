# gui_render.tcl -- the PVR GUI's rendering controls and saving (issue 14,
# point 9): shading on or off, the sampling step, the background colour, the
# shipped preset library, and saving the frame (PNG) or an animation
# (MP4 or GIF).
#
# The controls are `:s set` options (-shading, -step, -background,
# -tfpreset); each renders the view again. Saving reuses pvrsh's own file
# path (`:s image file`, docs/pvrsh.md): the current view is rendered once
# more with the file as a sink, or the rotation sequence of the "Rotation
# sequence" box is rendered into a movie, and the sink is removed when the
# request ends (::pvr::gui::render::requestEnded).
#
# Presets: the JSON files of the preset library (examples/presets in the
# repository, or the folder $env(PVR_PRESETS) names) are offered by name;
# choosing one sends the file's content (`-tfpreset FILE`), so the server
# needs no copy. The same files in the data directory's presets/ folder
# serve scenes that name them ("paraview_preset", docs/scene.md).

namespace eval ::pvr::gui::render {
    # Bound to the widgets: shading on (1) or off, the step ("" for the
    # server's default), the background as #rrggbb.
    variable shading 1
    variable step ""
    variable background #000000
    # The file a request in flight writes, "" for none; for an image, the
    # glob of the numbered PNG pvrsh writes first (`image file` numbers
    # every frame), which is then renamed to it.
    variable saving ""
    variable numbered ""
}

# ::pvr::gui::render::presetFolder --
#   The folder of the preset library.
proc ::pvr::gui::render::presetFolder {} {
    if {[info exists ::env(PVR_PRESETS)] && $::env(PVR_PRESETS) ne ""} {
        return $::env(PVR_PRESETS)
    }
    return [file normalize [file join $::pvr::gui::dir .. examples presets]]
}

# ::pvr::gui::render::presets --
#   The library as a dict: shown name (the file's stem, underscores as
#   spaces) -> file, in name order.
proc ::pvr::gui::render::presets {} {
    set library [dict create]
    foreach file [lsort [glob -nocomplain -directory [presetFolder] *.json]] {
        dict set library [string map {_ " "} [file rootname [file tail $file]]] $file
    }
    return $library
}

# ::pvr::gui::render::build --
#   The "Rendering" box in frame `f`: shading, step, background, presets,
#   and the save buttons.
proc ::pvr::gui::render::build {f} {
    ttk::labelframe $f -text "Rendering" -padding 4
    ttk::checkbutton $f.shading -text "shading" -variable ::pvr::gui::render::shading \
        -command ::pvr::gui::render::applyShading
    ttk::label $f.sl -text "step"
    ttk::entry $f.step -width 6 -textvariable ::pvr::gui::render::step
    bind $f.step <Return> ::pvr::gui::render::applyStep
    ttk::button $f.bg -text "Background\u2026" -command ::pvr::gui::render::chooseBackground
    ttk::menubutton $f.presets -text "Presets" -menu $f.presets.m
    menu $f.presets.m -tearoff 0
    dict for {name file} [presets] {
        $f.presets.m add command -label $name -command [list ::pvr::gui::loadPreset $file]
    }
    $f.presets.m add separator
    $f.presets.m add command -label "From file\u2026" -command ::pvr::gui::choosePreset
    ttk::button $f.save -text "Save image\u2026" -command ::pvr::gui::render::chooseImageFile
    ttk::button $f.movie -text "Save animation\u2026" -command ::pvr::gui::render::chooseMovieFile
    grid $f.shading $f.sl $f.step $f.bg $f.presets -padx 2 -pady 1 -sticky w
    grid $f.save - - $f.movie - -padx 2 -pady 1 -sticky w
    return $f
}

# ::pvr::gui::render::setAndRender --
#   `:s set WORDS`, then a frame of the current view; `what` names the
#   setting on the status line. Results: 1 when set.
proc ::pvr::gui::render::setAndRender {what words} {
    if {!$::pvr::gui::connected} {
        ::pvr::gui::status "$what: not connected (press Connect)" error
        return 0
    }
    if {[catch {$::pvr::gui::session set {*}$words} message]} {
        ::pvr::gui::status "$what: $message" error
        return 0
    }
    ::pvr::gui::status "$what: [join $words { }]"
    ::pvr::gui::requestFrame
    return 1
}

proc ::pvr::gui::render::applyShading {} {
    variable shading
    setAndRender shading [list -shading [expr {$shading ? "on" : "off"}]]
}

proc ::pvr::gui::render::applyStep {} {
    variable step
    if {![string is double -strict $step] || $step <= 0} {
        ::pvr::gui::status "step must be a number > 0 (world units), got '$step'" error
        return 0
    }
    setAndRender step [list -step $step]
}

# ::pvr::gui::render::applyBackground --
#   `colour` (#rrggbb) as the frames' background.
proc ::pvr::gui::render::applyBackground {colour} {
    variable background
    if {![regexp {^#([0-9a-fA-F]{2})([0-9a-fA-F]{2})([0-9a-fA-F]{2})$} $colour -> r g b]} {
        ::pvr::gui::status "background must be #rrggbb, got '$colour'" error
        return 0
    }
    set rgb [lmap c [list $r $g $b] {format %.4f [expr {[scan $c %x] / 255.0}]}]
    if {[setAndRender background [list -background [join $rgb ,]]]} {
        set background $colour
        return 1
    }
    return 0
}

proc ::pvr::gui::render::chooseBackground {} {
    variable background
    set colour [tk_chooseColor -initialcolor $background -title "Background colour"]
    if {$colour ne ""} {
        applyBackground $colour
    }
}

# ---- Saving ----

proc ::pvr::gui::render::chooseImageFile {} {
    set file [tk_getSaveFile -title "Save image" -defaultextension .png -filetypes {{{PNG image} {.png}}}]
    if {$file ne ""} {
        saveImage $file
    }
}

proc ::pvr::gui::render::chooseMovieFile {} {
    set file [tk_getSaveFile -title "Save animation (the rotation sequence)" -defaultextension .mp4 \
                  -filetypes {{{MP4 video} {.mp4}} {{GIF animation} {.gif}}}]
    if {$file ne ""} {
        saveAnimation $file
    }
}

# ::pvr::gui::render::startSaving --
#   Makes `file` the session's image file for the next request. Results: 1
#   when set (the status line says why not otherwise).
proc ::pvr::gui::render::startSaving {what file {sink ""}} {
    variable saving
    if {$sink eq ""} {
        set sink $file
    }
    if {!$::pvr::gui::connected} {
        ::pvr::gui::status "$what: not connected (press Connect)" error
        return 0
    }
    if {$::pvr::gui::view::busy} {
        ::pvr::gui::status "$what: a request is in flight; save when it ends" error
        return 0
    }
    if {[catch {$::pvr::gui::session image file $sink} message]} {
        ::pvr::gui::status "$what: $message" error
        return 0
    }
    set saving $file
    return 1
}

# ::pvr::gui::render::saveImage --
#   Renders the current view once more into the PNG `file`.
proc ::pvr::gui::render::saveImage {file} {
    variable numbered
    if {[string tolower [file extension $file]] ne ".png"} {
        ::pvr::gui::status "save image: frames are PNG files (8-bit sRGB); name a .png file, not [file tail $file]" error
        return 0
    }
    # Frame N goes to .pvr-save-PID-N.png beside the file, then becomes it.
    set stem [file join [file dirname $file] .pvr-save-[pid]]
    foreach old [glob -nocomplain $stem-*.png] {
        file delete $old
    }
    if {![startSaving "save image" $file $stem-%d.png]} {
        return 0
    }
    set numbered $stem-*.png
    # One frame, at full quality: not an interactive render's two.
    ::pvr::gui::requestFrame full
    return 1
}

# ::pvr::gui::render::saveAnimation --
#   Renders the rotation sequence into `file` (.mp4 or .gif, which pvrsh
#   assembles with ffmpeg when the sequence ends).
proc ::pvr::gui::render::saveAnimation {file} {
    if {![startSaving "save animation" $file]} {
        return 0
    }
    if {![::pvr::gui::renderSequence]} {
        stopSaving
        return 0
    }
    return 1
}

proc ::pvr::gui::render::stopSaving {} {
    variable saving
    variable numbered
    set saving ""
    set numbered ""
    catch {$::pvr::gui::session image file ""}
}

# ::pvr::gui::render::requestEnded --
#   A request ended (`event`: done, cancelled or error): a file being saved
#   is complete (done) or not, and the sink is removed.
proc ::pvr::gui::render::requestEnded {event} {
    variable saving
    if {$saving eq ""} {
        return
    }
    variable numbered
    set file $saving
    set written [expr {$numbered eq "" ? {} : [glob -nocomplain $numbered]}]
    stopSaving
    if {[llength $written] == 1} {
        if {$event eq "done"} {
            file rename -force [lindex $written 0] $file
        } else {
            file delete [lindex $written 0]
        }
    }
    if {$event eq "done" && [file exists $file]} {
        ::pvr::gui::status "saved [file tail $file] ([file size $file] bytes)"
    } else {
        ::pvr::gui::status "not saved: [file tail $file] ($event)" error
    }
}
