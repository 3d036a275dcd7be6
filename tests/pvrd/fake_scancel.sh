#!/bin/sh
# A stand-in for scancel in the daemon process tests (pvrd --scancel): it
# appends its arguments, one call per line, to the file FAKE_SCANCEL_LOG.
echo "$@" >> "$FAKE_SCANCEL_LOG"
