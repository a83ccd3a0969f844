"""The one assertion helper of the Python tests.

check(cond, message) prints "ok: message" when cond holds, else "FAIL: message" and ends
the test with exit status 1 (pdrun keeps its temporary folders for inspection then). A
test that surveys many files and reports every failure before ending calls keep_going()
first and finish() last: failures are then counted and finish() exits with 1 if any.

inconclusive(message) ends a run that judged too little to say pass or fail (a real-time test
whose sender the machine stalled past its lookahead, every late strike reported as such):
exit status INCONCLUSIVE (75, sysexits' EX_TEMPFAIL), which `python3 -m ictus_tools.retry`
answers by running the test again, a bounded number of times."""
import sys

INCONCLUSIVE = 75

_keep_going = [False]
_failures = []


def keep_going():
    """From now on a failed check is counted, not fatal: finish() ends the test."""
    _keep_going[0] = True


def check(cond, message):
    """Asserts cond; returns it (in keep_going mode a failure returns False)."""
    if cond:
        print("ok:", message)
        return True
    print("FAIL:", message)
    _failures.append(message)
    if not _keep_going[0]:
        sys.exit(1)
    return False


def fail(message):
    """A failure without a condition: prints "FAIL: message" and ends the test."""
    print("FAIL:", message)
    _failures.append(message)
    sys.exit(1)


def inconclusive(message):
    """Ends a run that judged too little: prints "INCONCLUSIVE: message", exit status 75."""
    print("INCONCLUSIVE:", message)
    sys.stdout.flush()
    sys.exit(INCONCLUSIVE)


def failed():
    """Whether any check failed so far."""
    return bool(_failures)


def finish():
    """Ends a keep_going test: exit status 1 if a check failed."""
    if _failures:
        print("%d check(s) failed" % len(_failures))
        sys.exit(1)
