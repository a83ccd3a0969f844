"""The one assertion helper of the Python tests.

check(cond, message) prints "ok: message" when cond holds, else "FAIL: message" and ends
the test with exit status 1 (pdrun keeps its temporary folders for inspection then). A
test that surveys many files and reports every failure before ending calls keep_going()
first and finish() last: failures are then counted and finish() exits with 1 if any."""
import sys

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


def failed():
    """Whether any check failed so far."""
    return bool(_failures)


def finish():
    """Ends a keep_going test: exit status 1 if a check failed."""
    if _failures:
        print("%d check(s) failed" % len(_failures))
        sys.exit(1)
