# gui_view.tcl -- the camera of the PVR GUI: azimuth/elevation from mouse
# drags and buttons, turned into render requests that never pile up.
#
# The GUI does not know the volume's bounds, so it does not place the eye
# itself. It orbits the server's automatic camera instead (docs/scene.md:
# looking at the centre of the domain from -y, turned 30 degrees in azimuth
# about +z, raised 20 degrees, up +z): any orbit position is one rotation of
# that camera about its look-at point (Euler's rotation theorem), and
# `:s render rotate AXIS K,K:N` renders exactly one frame of the base camera
# rotated by K/N of a turn about AXIS. The rotation that takes the base view
# to azimuth A, elevation E is R = F(A,E) * F(A0,E0)^T, where F is the
# orthonormal frame {view direction, right, up} of an orbit camera.
#
# Coalescing: at most one request is in flight. A drag that moves while a
# frame is being rendered only records the newest angles; when the frame
# arrives (or fails) the newest angles are sent, once.

namespace eval ::pvr::gui::view {
    # The automatic camera's angles (degrees), docs/scene.md "camera".
    variable baseAzimuth 30.0
    variable baseElevation 20.0
    # Steps per turn in the rotate request: 0.01 degree resolution.
    variable stepsPerTurn 36000
    # Degrees per pixel of drag.
    variable degreesPerPixel 0.5
}

# ---- Vector helpers on 3-lists ----

proc ::pvr::gui::view::cross {a b} {
    lassign $a ax ay az
    lassign $b bx by bz
    return [list [expr {$ay * $bz - $az * $by}] [expr {$az * $bx - $ax * $bz}] [expr {$ax * $by - $ay * $bx}]]
}

proc ::pvr::gui::view::normalize {v} {
    lassign $v x y z
    set n [expr {sqrt($x * $x + $y * $y + $z * $z)}]
    return [list [expr {$x / $n}] [expr {$y / $n}] [expr {$z / $n}]]
}

# ::pvr::gui::view::frame --
#   The orbit camera's frame at azimuth `az`, elevation `el` (degrees): the
#   direction from the look-at point to the eye, the right vector and the
#   up vector, as a list of three 3-lists.
proc ::pvr::gui::view::frame {az el} {
    set a [expr {$az * acos(-1) / 180.0}]
    set e [expr {$el * acos(-1) / 180.0}]
    # Azimuth 0 looks from -y; positive azimuth turns the eye towards +x.
    set d [list [expr {cos($e) * sin($a)}] [expr {-cos($e) * cos($a)}] [expr {sin($e)}]]
    set r [normalize [cross {0 0 1} $d]]
    set u [cross $d $r]
    return [list $d $r $u]
}

# ::pvr::gui::view::rotation --
#   The rotation taking the automatic camera to (az, el), as {axis degrees}
#   with the angle in [0, 180]; {{0 0 1} 0.0} for none.
proc ::pvr::gui::view::rotation {az el} {
    variable baseAzimuth
    variable baseElevation
    set F [frame $az $el]
    set F0 [frame $baseAzimuth $baseElevation]
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
#   when the view is the automatic camera's own (then `render frame`).
proc ::pvr::gui::view::rotateArgs {az el} {
    variable stepsPerTurn
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
    variable azimuth 30.0
    variable elevation 20.0
    variable busy 0
    variable dirty 0
    variable drag {}
    # The command prefix that sends one render request; it gets the words
    # after `render` ("frame" or "rotate AXIS K,K:N") appended.
    variable sender {}
    # Requests sent and drags coalesced away, for tests and the status line.
    variable sent 0
    variable coalesced 0
}

# ::pvr::gui::view::attach --
#   Binds drags on widget `w` to the view; `sender` sends one request.
proc ::pvr::gui::view::attach {w command} {
    variable sender
    set sender $command
    bind $w <ButtonPress-1> [list ::pvr::gui::view::dragStart %x %y]
    bind $w <B1-Motion> [list ::pvr::gui::view::dragMotion %x %y]
    bind $w <ButtonRelease-1> [list ::pvr::gui::view::dragEnd %x %y]
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
#   Back to the automatic camera, and a frame.
proc ::pvr::gui::view::reset {} {
    variable azimuth
    variable elevation
    variable baseAzimuth
    variable baseElevation
    set azimuth $baseAzimuth
    set elevation $baseElevation
    request
}

# ::pvr::gui::view::request --
#   Sends a frame of the current view now, or records that one is wanted
#   when a request is in flight.
proc ::pvr::gui::view::request {} {
    variable busy
    variable dirty
    variable sender
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
    set rotate [rotateArgs $azimuth $elevation]
    set words [expr {$rotate eq {} ? {frame} : [linsert $rotate 0 rotate]}]
    set busy 1
    if {[catch {uplevel #0 [concat $sender $words]} message options]} {
        set busy 0
        return -options $options $message
    }
    incr sent
}

# ::pvr::gui::view::finished --
#   The request in flight is over (its frame arrived, or it failed, or was
#   cancelled); sends the newest view if it changed meanwhile.
proc ::pvr::gui::view::finished {} {
    variable busy
    variable dirty
    set busy 0
    if {$dirty} {
        request
    }
}
