# A rotation long enough to lose a host in the middle of it (run with
# pvrsh -nogui on h0):
#
#   lost.tcl HOST:PORT RANKS DATASET MARKER
#
# After its third frame the session creates the file MARKER (the test then
# kills a host) and waits up to 60 s for the error the loss must bring.
# Prints on stdout
#   error_at MS      [clock milliseconds] when wait raised the error
#   errorcode CODE   its -errorcode
#   message TEXT     its message
# and exits 0; a rotation that ends without an error exits 1.
lassign $argv server ranks dataset marker

proc arrived {frame timing} {
    if {$frame == 2} { close [open $::marker w] }
}

pvr_session :l
:l image callback arrived
:l open $server -ranks $ranks -timeout 60
:l set -dataset $dataset -imagesz 96,96 -background 0,0,0 \
    -tf {0 0 0 0 0  0.3 0.2 0.4 1 0.05  0.6 1 0.8 0.2 0.3  1 1 1 1 0.8}
:l render rotate 0,0,1 0,9999:10000
if {![catch {:l wait -timeout 60} message options]} {
    puts stderr "lost.tcl: all frames arrived: no host was lost"
    exit 1
}
puts "error_at [clock milliseconds]"
puts "errorcode [dict get $options -errorcode]"
puts "message $message"
