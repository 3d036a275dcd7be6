# A stand-in pvrd for tests of what pvrsh does with answers a real pvrd
# gives only in situations a test cannot make at will (a session waiting in
# a Slurm queue), and with a hostile or broken server (frames pvrsh cannot
# deliver, a Close that leaves the socket open, half a frame, a catalog over
# the protocol's limit). It listens on 127.0.0.1, speaks the frames of
# docs/protocol.md in Tcl on the test's own event loop, answers Hello with
# Welcome, SessionOpen with the frames the test scripted, StatusRequest as
# a master of three ranks on two hosts would (state, hosts), SetScene and
# SetLayout with Ok, Cancel with Ok, CatalogRequest with a catalog of
# ::fakepvrd::catalogBytes payload bytes (0: one dataset, "ball"), and each
# render request with its frames, 2 x 2 RGB8, as ::fakepvrd::renders says.
#
#   set port [::fakepvrd::start {{progress {state queued batch_job 12 reason Priority}} ready}]
#   ... :s open 127.0.0.1:$port ...
#   ::fakepvrd::stop
#
# Script steps: `progress KEYVALUES` sends a StatusReply that is not FINAL,
# `ready` sends SessionReady, `error CODE TEXT` sends Error; each carries
# the SessionOpen's request id. ::fakepvrd::received holds, per request the
# server read, {type id fields}: for SessionOpen the fields are
# {rankCount clusterCount account}, for SetScene (type 18) {dataset
# sceneJson}, for Cancel {target}, for a render {frames}.
#
# ::fakepvrd::renders: one entry per render request, in order (requests
# past the list get `frames {}`):
#   frames BAD   every frame of the request; those numbered in the list BAD
#                have zlib pixels that do not decompress
#   close REASON Close (request id 0) instead of frames; the socket stays open
#   half         the header and part of the first frame's payload, then nothing
#
# ::fakepvrd::sceneAnswers: one entry per SetScene, in order (those past
# the list are accepted): `ok`, or `error CODE TEXT` to refuse it.
namespace eval ::fakepvrd {
    variable listen ""
    variable script {}
    variable received {}
    variable buffers
    array set buffers {}
    variable types {Hello 0x01 Welcome 0x02 Ok 0x05 Error 0x06 Close 0x07 SessionOpen 0x10 SessionReady 0x11
        ImageFrame 0x22 StatusReply 0x31 PerformanceReply 0x33 CatalogReply 0x35}
    variable renders {}
    variable catalogBytes 0
    variable sceneAnswers {}
}

# ::fakepvrd::start SCRIPT: listens on an ephemeral loopback port; returns it.
proc ::fakepvrd::start {script {renders {}} {catalogBytes 0}} {
    variable listen
    variable received {}
    set ::fakepvrd::script $script
    set ::fakepvrd::renders $renders
    set ::fakepvrd::catalogBytes $catalogBytes
    set ::fakepvrd::sceneAnswers {}
    set listen [socket -server ::fakepvrd::accept -myaddr 127.0.0.1 0]
    return [lindex [fconfigure $listen -sockname] 2]
}

proc ::fakepvrd::stop {} {
    variable listen
    variable buffers
    foreach ch [array names buffers] {
        catch {close $ch}
    }
    array unset buffers
    if {$listen ne ""} {
        close $listen
        set listen ""
    }
}

proc ::fakepvrd::accept {ch host port} {
    variable buffers
    fconfigure $ch -translation binary -blocking 0
    set buffers($ch) ""
    fileevent $ch readable [list ::fakepvrd::readable $ch]
}

# Wire pieces (little-endian): str is u32 length + UTF-8 bytes.
proc ::fakepvrd::str {s} {
    set bytes [encoding convertto utf-8 $s]
    return [binary format i [string length $bytes]]$bytes
}

proc ::fakepvrd::frame {type id final payload} {
    variable types
    set header [binary format c4ccsii {0x89 0x50 0x56 0x52} 1 [dict get $types $type] \
        [expr {$final ? 1 : 0}] $id [string length $payload]]
    return $header$payload
}

proc ::fakepvrd::send {ch type id final payload} {
    puts -nonewline $ch [frame $type $id $final $payload]
    flush $ch
}

proc ::fakepvrd::readable {ch} {
    variable buffers
    if {[catch {read $ch} data] || ([eof $ch] && $data eq "")} {
        catch {close $ch}
        unset -nocomplain buffers($ch)
        return
    }
    append buffers($ch) $data
    # Every whole frame in the buffer: a 16-byte header, then its payload.
    while {[string length $buffers($ch)] >= 16} {
        binary scan $buffers($ch) a4cucusuiuiu magic version type flags id length
        if {[string length $buffers($ch)] < 16 + $length} break
        set payload [string range $buffers($ch) 16 [expr {15 + $length}]]
        set buffers($ch) [string range $buffers($ch) [expr {16 + $length}] end]
        request $ch $type $id $payload
    }
}

proc ::fakepvrd::request {ch type id payload} {
    variable received
    variable script
    switch -- $type {
        1 {
            lappend received [list Hello $id {}]
            # Welcome: software, maxRanks 8, no authentication.
            send $ch Welcome $id 1 [str "fake pvrd"][binary format ic 8 0]
        }
        16 {
            # SessionOpen: u32 rankCount, list<Cluster> (9 bytes each), str account.
            binary scan $payload iuiu ranks clusters
            set at [expr {8 + 9 * $clusters}]
            binary scan $payload @${at}iu n
            set account [encoding convertfrom utf-8 [string range $payload [expr {$at + 4}] [expr {$at + 3 + $n}]]]
            lappend received [list SessionOpen $id [list $ranks $clusters $account]]
            foreach step $script {
                switch -- [lindex $step 0] {
                    progress {
                        set entries [binary format i [expr {[llength [lindex $step 1]] / 2}]]
                        foreach {k v} [lindex $step 1] {
                            append entries [str $k] [str $v]
                        }
                        send $ch StatusReply $id 0 $entries
                    }
                    ready {
                        send $ch SessionReady $id 1 [binary format ii [lindex $received end 2 0] 0]
                    }
                    error {
                        send $ch Error $id 1 [binary format s [lindex $step 1]][str [lindex $step 2]]
                    }
                }
            }
        }
        48 {
            # StatusRequest: what a master of three ranks on two hosts says.
            lappend received [list StatusRequest $id {}]
            send $ch StatusReply $id 1 [binary format i 2][str state][str {session open}][str hosts][str {h1 h1 h2}]
        }
        18 - 19 {
            # SetScene, SetLayout: accepted, or a SetScene answered as
            # ::fakepvrd::sceneAnswers says.
            if {$type == 18} {
                # str dataset, str sceneJson
                binary scan $payload iu n
                set dataset [encoding convertfrom utf-8 [string range $payload 4 [expr {3 + $n}]]]
                binary scan $payload @[expr {4 + $n}]iu m
                set json [encoding convertfrom utf-8 [string range $payload [expr {8 + $n}] [expr {7 + $n + $m}]]]
                lappend received [list 18 $id [list $dataset $json]]
            } else {
                lappend received [list $type $id {}]
            }
            variable sceneAnswers
            set answer ok
            if {$type == 18 && [llength $sceneAnswers] > 0} {
                set answer [lindex $sceneAnswers 0]
                set sceneAnswers [lrange $sceneAnswers 1 end]
            }
            if {[lindex $answer 0] eq "error"} {
                send $ch Error $id 1 [binary format s [lindex $answer 1]][str [lindex $answer 2]]
            } else {
                send $ch Ok $id 1 ""
            }
        }
        32 - 33 - 36 - 38 {
            # RenderFrame (1 frame), RenderRotation (E - S + 1), RenderTimeSteps,
            # RenderInteractive (the coarse frame, then the full one).
            set count 1
            if {$type == 38} {
                set count 2
            } elseif {$type == 33} {
                binary scan $payload @24ii start end
                set count [expr {$end - $start + 1}]
            } elseif {$type == 36} {
                binary scan $payload iuiuiu first last stride
                set count [expr {($last - $first) / $stride + 1}]
            }
            lappend received [list Render $id $count]
            render $ch $id $count
        }
        35 {
            # Cancel: u32 target. Ok, as pvrd answers it.
            binary scan $payload iu target
            lappend received [list Cancel $id $target]
            send $ch Ok $id 1 ""
        }
        50 {
            # PerformanceRequest: a reply whose JSON nests 100000 arrays
            # deep (700 KB), as a hostile server might send.
            lappend received [list PerformanceRequest $id {}]
            binary scan $payload cu query
            set json [string repeat \[ 100000][string repeat \] 100000]
            send $ch PerformanceReply $id 1 [binary format c $query][str $json]
        }
        52 {
            lappend received [list CatalogRequest $id {}]
            send $ch CatalogReply $id 1 [catalog]
        }
        default {
            lappend received [list $type $id {}]
        }
    }
}

# An ImageFrame payload: frame NUMBER, 2 x 2 RGB8; BAD: zlib pixels that
# do not decompress (fewer bytes than raw, so the frame itself is valid).
proc ::fakepvrd::imageFrame {number bad} {
    if {$bad} {
        set compression 2
        set pixels [binary format c5 {1 2 3 4 5}]
    } else {
        set compression 0
        set pixels [binary format c12 {10 20 30 40 50 60 70 80 90 100 110 120}]
    }
    return [binary format iiiccqqqqqqq $number 2 2 0 $compression 0 0 0 0.01 0 0 0][binary format i [string length $pixels]]$pixels
}

proc ::fakepvrd::render {ch id count} {
    variable renders
    set what {frames {}}
    if {[llength $renders] > 0} {
        set what [lindex $renders 0]
        set renders [lrange $renders 1 end]
    }
    switch -- [lindex $what 0] {
        frames {
            for {set k 0} {$k < $count} {incr k} {
                send $ch ImageFrame $id [expr {$k == $count - 1}] [imageFrame $k [expr {$k in [lindex $what 1]}]]
            }
        }
        close {
            send $ch Close 0 1 [str [lindex $what 1]]
        }
        half {
            set frame [frame ImageFrame $id 1 [imageFrame 0 0]]
            puts -nonewline $ch [string range $frame 0 [expr {16 + 20 - 1}]]
            flush $ch
        }
    }
}

# A CatalogReply payload: one dataset, "ball", or with catalogBytes > 0 one
# whose name makes the payload exactly that long (u32 count, str name, u32 steps).
proc ::fakepvrd::catalog {} {
    variable catalogBytes
    if {$catalogBytes <= 0} {
        return [binary format i 1][str ball][binary format i 1]
    }
    return [binary format i 1][str [string repeat d [expr {$catalogBytes - 12}]]][binary format i 1]
}
