#!/bin/sh
# A stand-in for salloc in the daemon process tests (pvrd --salloc). pvrd
# runs it as
#   fake_salloc.sh --ntasks=N ... --job-name=NAME --kill-command=TERM MPIRUN...
# Every salloc option is one word (slurm_launcher.h), so the command starts
# at the first word without a leading '-'. It prints salloc 22.05's lines
# for a queued request and then, as FAKE_SALLOC_OUTCOME says:
#   granted (default)  the grant, then it becomes the command (exec);
#   cancelled          the pending request cancelled, exit 1;
#   revoked            the grant, runs the command, and once the file
#                      FAKE_SALLOC_REVOKE_WHEN exists the allocation is
#                      revoked: the command is killed, exit 1.
# It leaves the queue once the file FAKE_SALLOC_GRANT_WHEN exists (none:
# after a second). The job id is FAKE_SALLOC_JOB (default 4242).
job=${FAKE_SALLOC_JOB:-4242}
while [ $# -gt 0 ] && [ "${1#-}" != "$1" ]; do shift; done

waitFor() {
  while [ ! -e "$1" ]; do sleep 0.05; done
}

echo "salloc: Pending job allocation $job" >&2
echo "salloc: job $job queued and waiting for resources" >&2
if [ -n "$FAKE_SALLOC_GRANT_WHEN" ]; then waitFor "$FAKE_SALLOC_GRANT_WHEN"; else sleep 1; fi
if [ "$FAKE_SALLOC_OUTCOME" = cancelled ]; then
  echo "salloc: Job has been cancelled" >&2
  echo "salloc: error: Job submit/allocate failed: Job/step already completing or completed" >&2
  exit 1
fi
echo "salloc: job $job has been allocated resources" >&2
echo "salloc: Granted job allocation $job" >&2
if [ "$FAKE_SALLOC_OUTCOME" != revoked ]; then exec "$@"; fi
"$@" &
command=$!
waitFor "$FAKE_SALLOC_REVOKE_WHEN"
echo "salloc: Job allocation $job has been revoked." >&2
kill -TERM $command
wait $command
exit 1
