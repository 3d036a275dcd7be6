# gui_view.tcl -- the camera of the PVR GUI: azimuth/elevation from mouse
# drags and buttons, turned into render requests that never pile up.
#
# The GUI does not place the eye itself. It orbits the camera the server
# reports for the dataset (`list status`: camera_eye, camera_look_at,
# camera_up; the automatic camera unless a scene says otherwise). The
# orbit's vertical axis is that camera's up vector; the elevation is the
# eye's angle above the plane across it, the azimuth the turn about it
# from the reported eye (0 there). Any orbit position is one rotation of
# the reported camera about its look-at point (Euler's rotation theorem),
# and `:s render rotate AXIS K,K:N` renders exactly one frame of the scene's
# camera with its eye and up turned by K/N of a turn about AXIS through the
# look-at point (docs/protocol.md, RenderRotation). The rotation that takes
# the reported view to azimuth A, elevation E is R = F(A,E) * F(0,E0)^T,
# where F is the orthonormal frame {view direction, right, up} of an orbit
# camera and E0 the reported camera's elevation.
#
# Zoom (mouse wheel), pan (middle-button drag), the standard views and
# Reset are camera moves of `:s set` (-zoom, -pan, -view, -camera reset),
# which the server applies to the camera in force (docs/scene.md, "Moving
# the camera"). Before sending them, and before a rotation sequence, the
# orbit is committed the same way (-elevation E-E0 -azimuth A turn the
# reported camera exactly as the orbit frame shows it), and the new
# camera becomes the orbit's base: so the server's camera is the view on
# screen, and a sequence starts from it.
#
# Coalescing: at most one request waits for its first frame. A drag that
# moves meanwhile only records the newest angles; when the frame arrives
# (or the request fails) the newest angles are sent, once.
#
# Progressive refinement: the requests are interactive renders (`render
# ... -interactive`, docs/pvrsh.md): a coarse frame comes first, and the
# full-quality frame follows unless the view moved on. The next view goes
# out as soon as the coarse frame arrives (firstFrame), superseding the
# full one, so a drag shows coarse frames at the coarse rate and, when it
# stops, the full frame of where it stopped.

namespace eval ::pvr::gui::view {
    # The reported camera as the orbit's basis: unit vectors up (the
    # vertical axis), ahead (from the look-at point towards the eye, across
    # the vertical) and side (up x ahead, towards positive azimuth), and the
    # eye's elevation in degrees. Empty until the server has reported one.
    variable base {}
    variable baseElevation 0.0
    # The command that returns the server's camera as {eye look_at up}
    # ({} when it has none); asked before a request when base is empty.
    variable cameraSource {}
    # Steps per turn in the rotate request: 0.01 degree resolution.
    variable stepsPerTurn 36000
    # Degrees per pixel of drag.
    variable degreesPerPixel 0.5
    # The command prefix that sets session options (`:s set`), and the
    # camera moves waiting for the next request, as its words.
    variable setter {}
    variable moves {}
    # Magnification per wheel step.
    variable zoomStep 1.25
}

# ---- Vector helpers on 3-lists ----

proc ::pvr::gui::view::cross {a b} {
    lassign $a ax ay az
    lassign $b bx by bz
    return [list [expr {$ay * $bz - $az * $by}] [expr {$az * $bx - $ax * $bz}] [expr {$ax * $by - $ay * $bx}]]
}

proc ::pvr::gui::view::dot {a b} {
    lassign $a ax ay az
    lassign $b bx by bz
    return [expr {$ax * $bx + $ay * $by + $az * $bz}]
}

# a + s * b
proc ::pvr::gui::view::addScaled {a s b} {
    return [lmap x $a y $b {expr {$x + $s * $y}}]
}

proc ::pvr::gui::view::normalize {v} {
    lassign $v x y z
    set n [expr {sqrt($x * $x + $y * $y + $z * $z)}]
    return [list [expr {$x / $n}] [expr {$y / $n}] [expr {$z / $n}]]
}

# ::pvr::gui::view::setBase --
#   Makes the camera at `eye` looking at `lookAt` with `up` the orbit's
#   base, at azimuth 0 and its own elevation. Results: 1, or 0 (and no
#   base) when the three do not make a camera.
proc ::pvr::gui::view::setBase {eye lookAt up} {
    variable base
    variable baseElevation
    variable azimuth
    variable elevation
    set base {}
    if {[llength $eye] != 3 || [llength $lookAt] != 3 || [llength $up] != 3} {
        return 0
    }
    set toEye [addScaled $eye -1 $lookAt]
    if {[dot $toEye $toEye] == 0 || [dot $up $up] == 0} {
        return 0
    }
    set v [normalize $up]
    set d [normalize $toEye]
    set sinE [dot $d $v]
    set across [addScaled $d [expr {-$sinE}] $v]
    if {[dot $across $across] < 1e-12} {
        # Looking along the up vector: a camera refuses it (docs/scene.md).
        return 0
    }
    set ahead [normalize $across]
    set base [list $v $ahead [cross $v $ahead]]
    set baseElevation [expr {asin(max(-1.0, min(1.0, $sinE))) * 180.0 / acos(-1)}]
    set azimuth 0.0
    set elevation $baseElevation
    return 1
}

# ::pvr::gui::view::frame --
#   The orbit camera's frame at azimuth `az`, elevation `el` (degrees): the
#   direction from the look-at point to the eye, the right vector and the
#   up vector, as a list of three 3-lists. Needs a base.
proc ::pvr::gui::view::frame {az el} {
    variable base
    lassign $base up ahead side
    set a [expr {$az * acos(-1) / 180.0}]
    set e [expr {$el * acos(-1) / 180.0}]
    # Positive azimuth turns the eye from `ahead` towards `side`.
    set d [lmap h $ahead s $side v $up {expr {cos($e) * (cos($a) * $h + sin($a) * $s) + sin($e) * $v}}]
    set r [normalize [cross $up $d]]
    set u [cross $d $r]
    return [list $d $r $u]
}

# ::pvr::gui::view::rotation --
#   The rotation taking the reported camera to (az, el), as {axis degrees}
#   with the angle in [0, 180]; {{0 0 1} 0.0} for none.
proc ::pvr::gui::view::rotation {az el} {
    variable baseElevation
    set F [frame $az $el]
    set F0 [frame 0.0 $baseElevation]
    # R[i][j] = sum over the frame vectors k of F[k][i] * F0[k][j].
    for {set i 0} {$i < 3} {incr i} {
        for {set j 0} {$j < 3} {incr j} {
            set s 0.0
            for {set k 0} {$k < 3} {incr k} {
                set s [expr {$s + [lindex $F $k $i] * [lindex $F0 $k $j]}]
            }
            set R($i,$j) $s
        }
    }
    set cosA [expr {max(-1.0, min(1.0, ($R(0,0) + $R(1,1) + $R(2,2) - 1) / 2.0))}]
    set angle [expr {acos($cosA)}]
    if {$angle < 1e-9} {
        return [list {0 0 1} 0.0]
    }
    if {$angle > acos(-1) - 1e-6} {
        # Half a turn: R = 2 k k^T - I, so k comes from the diagonal, with
        # the signs of the largest component's row.
        set m 0
        foreach i {1 2} {
            if {$R($i,$i) > $R($m,$m)} {
                set m $i
            }
        }
        set km [expr {sqrt(max(0.0, ($R($m,$m) + 1) / 2.0))}]
        set k {}
        foreach i {0 1 2} {
            lappend k [expr {$i == $m ? $km : $R($m,$i) / (2 * $km)}]
        }
        return [list [normalize $k] 180.0]
    }
    set s [expr {2 * sin($angle)}]
    set k [list [expr {($R(2,1) - $R(1,2)) / $s}] [expr {($R(0,2) - $R(2,0)) / $s}] [expr {($R(1,0) - $R(0,1)) / $s}]]
    return [list [normalize $k] [expr {$angle * 180.0 / acos(-1)}]]
}

# ::pvr::gui::view::rotateArgs --
#   The arguments of `:s render rotate` for one frame at (az, el), or {}
#   when the view is the reported camera's own or no camera is known yet
#   (then `render frame`).
proc ::pvr::gui::view::rotateArgs {az el} {
    variable stepsPerTurn
    variable base
    if {$base eq {}} {
        return {}
    }
    lassign [rotation $az $el] axis degrees
    set k [expr {int(round($degrees / 360.0 * $stepsPerTurn))}]
    if {$k == 0} {
        return {}
    }
    set axisText [join [lmap c $axis {format %.9f $c}] ,]
    return [list $axisText $k,$k:$stepsPerTurn]
}

# ---- The view state of the GUI and its requests ----

namespace eval ::pvr::gui::view {
    # azimuth, elevation: the view wanted; busy: a request is in flight;
    # dirty: the view changed while busy; drag: last pointer position.
    variable azimuth 0.0
    variable elevation 0.0
    variable busy 0
    variable dirty 0
    # Requests sent whose end (done or cancelled) has not come yet, and
    # whether requests are interactive renders.
    variable pending 0
    variable interactive 1
    variable drag {}
    # The command prefix that sends one render request; it gets the words
    # after `render` ("frame" or "rotate AXIS K,K:N") appended.
    variable sender {}
    # Requests sent and drags coalesced away, for tests and the status line.
    variable sent 0
    variable coalesced 0
}

# ::pvr::gui::view::attach --
#   Binds drags on widget `w` to the view; `command` sends one request,
#   `camera` returns the server's camera (see cameraSource).
#   `set` sets session options (camera moves).
proc ::pvr::gui::view::attach {w command camera set} {
    variable sender
    variable cameraSource
    variable setter
    set sender $command
    set cameraSource $camera
    set setter $set
    bind $w <ButtonPress-1> [list ::pvr::gui::view::dragStart %x %y]
    bind $w <B1-Motion> [list ::pvr::gui::view::dragMotion %x %y]
    bind $w <ButtonRelease-1> [list ::pvr::gui::view::dragEnd %x %y]
    # The wheel: Button-4/5 on X11, <MouseWheel> with a delta elsewhere.
    bind $w <Button-4> {::pvr::gui::view::wheel 1}
    bind $w <Button-5> {::pvr::gui::view::wheel -1}
    bind $w <MouseWheel> {::pvr::gui::view::wheel %D}
    bind $w <ButtonPress-2> [list ::pvr::gui::view::panStart %x %y]
    bind $w <B2-Motion> [list ::pvr::gui::view::panMotion %W %x %y]
    bind $w <ButtonRelease-2> [list ::pvr::gui::view::panEnd %W %x %y]
}

# ::pvr::gui::view::move --
#   Queues the camera move `option value` (a `:s set` pair) and asks for a
#   frame. Consecutive zooms multiply and consecutive pans add, so a fast
#   wheel or drag sends one move.
proc ::pvr::gui::view::move {option value} {
    variable moves
    lassign [lrange $moves end-1 end] lastOption lastValue
    if {$option eq "-zoom" && $lastOption eq "-zoom"} {
        lset moves end [expr {$lastValue * $value}]
    } elseif {$option eq "-pan" && $lastOption eq "-pan"} {
        lset moves end [join [lmap a [split $lastValue ,] b [split $value ,] {expr {$a + $b}}] ,]
    } elseif {$option eq "-camera" || $option eq "-view"} {
        # They replace the orientation: what was queued before is moot.
        set moves [list $option $value]
    } else {
        lappend moves $option $value
    }
    request
}

# One wheel step in (delta > 0) or out.
proc ::pvr::gui::view::wheel {delta} {
    variable zoomStep
    if {$delta == 0} {
        return
    }
    move -zoom [expr {$delta > 0 ? $zoomStep : 1.0 / $zoomStep}]
}

# Middle-button drag: the image follows the pointer, so the camera moves
# the other way, in fractions of the widget's size.
proc ::pvr::gui::view::panStart {x y} {
    variable panFrom
    set panFrom [list $x $y]
}

proc ::pvr::gui::view::panMotion {w x y} {
    variable panFrom
    if {![info exists panFrom] || $panFrom eq {}} {
        set panFrom [list $x $y]
        return
    }
    lassign $panFrom x0 y0
    set panFrom [list $x $y]
    set width [expr {max(1, [winfo width $w])}]
    set height [expr {max(1, [winfo height $w])}]
    if {$x == $x0 && $y == $y0} {
        return
    }
    move -pan [format %.6f,%.6f [expr {-($x - $x0) / double($width)}] [expr {($y - $y0) / double($height)}]]
}

proc ::pvr::gui::view::panEnd {w x y} {
    variable panFrom
    panMotion $w $x $y
    set panFrom {}
}

# ::pvr::gui::view::orbitWords --
#   The `:s set` words that turn the server's camera to the orbit's view,
#   or {} when it is the reported camera's own.
proc ::pvr::gui::view::orbitWords {} {
    variable base
    variable azimuth
    variable elevation
    variable baseElevation
    if {$base eq {} || ($azimuth == 0 && $elevation == $baseElevation)} {
        return {}
    }
    return [list -elevation [expr {$elevation - $baseElevation}] -azimuth $azimuth]
}

# ::pvr::gui::view::commit --
#   Makes the server's camera the view on screen (before a sequence): sets
#   the orbit on the server; the next request reads the camera again.
proc ::pvr::gui::view::commit {} {
    variable base
    variable setter
    set words [orbitWords]
    if {$words ne {} && $setter ne {}} {
        uplevel #0 [concat $setter $words]
        set base {}
    }
}

proc ::pvr::gui::view::dragStart {x y} {
    variable drag
    set drag [list $x $y]
}

# Horizontal drag turns the azimuth, vertical the elevation (clamped short
# of the poles, where the orbit's up vector flips).
proc ::pvr::gui::view::dragMotion {x y} {
    variable drag
    variable degreesPerPixel
    if {$drag eq {}} {
        set drag [list $x $y]
        return
    }
    lassign $drag x0 y0
    set drag [list $x $y]
    turn [expr {-($x - $x0) * $degreesPerPixel}] [expr {($y - $y0) * $degreesPerPixel}]
}

proc ::pvr::gui::view::dragEnd {x y} {
    variable drag
    if {$drag ne {}} {
        dragMotion $x $y
    }
    set drag {}
}

# ::pvr::gui::view::turn --
#   Changes the view by the given degrees and asks for a frame.
proc ::pvr::gui::view::turn {dAzimuth dElevation} {
    variable azimuth
    variable elevation
    if {$dAzimuth == 0 && $dElevation == 0} {
        return
    }
    set azimuth [expr {fmod($azimuth + $dAzimuth + 360.0, 360.0)}]
    set elevation [expr {max(-89.0, min(89.0, $elevation + $dElevation))}]
    request
}

# ::pvr::gui::view::reset --
#   Back to the automatic camera (`-camera reset`), and a frame.
proc ::pvr::gui::view::reset {} {
    move -camera reset
}

# ::pvr::gui::view::sceneChanged --
#   The server's camera may have changed (another dataset): it is asked
#   again before the next request, and the view starts from it.
proc ::pvr::gui::view::sceneChanged {} {
    variable base
    set base {}
}

# ::pvr::gui::view::request --
#   Sends a frame of the current view now, or records that one is wanted
#   when a request is in flight.
proc ::pvr::gui::view::request {{progressive 1}} {
    variable busy
    variable dirty
    variable sender
    variable base
    variable cameraSource
    variable azimuth
    variable elevation
    variable sent
    variable coalesced
    if {$busy} {
        if {$dirty} {
            incr coalesced
        }
        set dirty 1
        return
    }
    set dirty 0
    set busy 1
    if {[catch {
        variable moves
        variable setter
        if {$moves ne {} && $setter ne {}} {
            # The orbit first, then the moves, from the view on screen; a
            # reset or a standard view replaces it (pvrsh drops moves before
            # -camera reset), and the camera is read again.
            set words $moves
            set moves {}
            uplevel #0 [concat $setter [orbitWords] $words]
            set base {}
        }
        if {$base eq {} && $cameraSource ne {}} {
            set camera [uplevel #0 $cameraSource]
            if {[llength $camera] == 3} {
                setBase {*}$camera
            }
        }
        set rotate [rotateArgs $azimuth $elevation]
        set words [expr {$rotate eq {} ? {frame} : [linsert $rotate 0 rotate]}]
        variable interactive
        if {$interactive && $progressive} {
            lappend words -interactive
        }
        uplevel #0 [concat $sender $words]
    } message options]} {
        set busy 0
        return -options $options $message
    }
    incr sent
    variable pending
    incr pending
}

# ::pvr::gui::view::finished --
#   The request in flight is over (its frame arrived, or it failed, or was
#   cancelled; `all`: every request, the session ended); sends the newest
#   view if it changed meanwhile and no request waits for its first frame.
proc ::pvr::gui::view::finished {{all ""}} {
    variable busy
    variable dirty
    variable pending
    set pending [expr {$all eq "all" ? 0 : max(0, $pending - 1)}]
    if {$pending == 0} {
        set busy 0
    }
    if {$dirty && !$busy} {
        request
    }
}

# ::pvr::gui::view::firstFrame --
#   The coarse frame of the request in flight arrived: the newest view, if
#   it changed meanwhile by orbiting, goes out now and supersedes the full
#   frame. Camera moves wait for the request to end (finished): they read
#   the server's camera back, which pvrsh answers only between renders.
proc ::pvr::gui::view::firstFrame {} {
    variable busy
    variable dirty
    variable moves
    variable base
    if {$moves ne {} || $base eq {}} {
        return
    }
    set busy 0
    if {$dirty} {
        request
    }
}
