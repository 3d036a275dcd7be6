# A stand-in pvrd for tests of what pvrsh does with answers a real pvrd
# gives only in situations a test cannot make at will (a session waiting in
# a Slurm queue). It listens on 127.0.0.1, speaks the frames of
# docs/protocol.md in Tcl on the test's own event loop, answers Hello with
# Welcome, SessionOpen with the frames the test scripted, and StatusRequest
# as a master of three ranks on two hosts would (state, hosts).
#
#   set port [::fakepvrd::start {{progress {state queued batch_job 12 reason Priority}} ready}]
#   ... :s open 127.0.0.1:$port ...
#   ::fakepvrd::stop
#
# Script steps: `progress KEYVALUES` sends a StatusReply that is not FINAL,
# `ready` sends SessionReady, `error CODE TEXT` sends Error; each carries
# the SessionOpen's request id. ::fakepvrd::received holds, per request the
# server read, {type id fields}: for SessionOpen the fields are
# {rankCount clusterCount account}.

namespace eval ::fakepvrd {
    variable listen ""
    variable script {}
    variable received {}
    variable buffers
    array set buffers {}
    variable types {Hello 0x01 Welcome 0x02 Error 0x06 SessionOpen 0x10 SessionReady 0x11 StatusReply 0x31}
}

# ::fakepvrd::start SCRIPT: listens on an ephemeral loopback port; returns it.
proc ::fakepvrd::start {script} {
    variable listen
    variable received {}
    set ::fakepvrd::script $script
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
        default {
            lappend received [list $type $id {}]
        }
    }
}
