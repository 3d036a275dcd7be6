// The PVR wire protocol in one include: frames, messages, codec, incremental
// decoder, relay, image limits and the pixel codec. Pure C++: no sockets, no
// MPI, no Tcl.
// docs/protocol.md is the byte-level specification.
#pragma once

#include "frame_codec.h"
#include "frame_decoder.h"
#include "frame_relay.h"
#include "frame_header.h"
#include "image_limits.h"
#include "json_depth.h"
#include "message_table.h"
#include "pixel_codec.h"
#include "protocol_error.h"
#include "protocol_messages.h"
