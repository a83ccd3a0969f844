"""Runs a test again while it ends inconclusive (exit status 75, checks.inconclusive), at most
--attempts times in all; any other status ends it at once and is returned. A test that is
inconclusive on every attempt fails (status 1): the machine stalled it each time, or what it
measures is wrong in a way that looks like a stall (e.g. every strike late and reported late).

    python3 -m ictus_tools.retry [--attempts 3] -- COMMAND [ARGS...]
"""
import argparse
import subprocess
import sys

from ictus_tools.checks import INCONCLUSIVE


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--attempts", type=int, default=3)
    ap.add_argument("command", nargs=argparse.REMAINDER)
    args = ap.parse_args(argv)
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command or args.attempts < 1:
        ap.error("a command and --attempts >= 1 are needed")
    for attempt in range(1, args.attempts + 1):
        sys.stdout.flush()
        status = subprocess.call(command)
        if status != INCONCLUSIVE:
            return status
        print("retry: attempt %d of %d was inconclusive%s" % (
            attempt, args.attempts, "; running it again" if attempt < args.attempts else ""))
    print("FAIL: %d attempts in a row were inconclusive" % args.attempts)
    return 1


if __name__ == "__main__":
    sys.exit(main())
