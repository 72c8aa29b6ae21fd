"""The check harness of every Python test (tests/unit, tests/integration, tests/server, tests/clients, tests/mpi): named checks counted
in one process, a skip CTest understands, and the summary and exit code at the end.

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))  # tests/
    from checks import check, finish, skip

    check("the job solves", r.returncode == 0, r.stderr)   # a failure prints "FAIL name: detail"
    finish()                                               # "N passed, M failed"; exit 1 on a failure, else 0

Exit codes as tests/CMakeLists.txt expects them: 0 all passed, 1 a check failed, 77 skipped (SKIP_RETURN_CODE)."""
import contextlib
import sys
import time
import traceback

SKIP = 77  # tests/CMakeLists.txt: SKIP_RETURN_CODE
DETAIL_LIMIT = 2000  # characters of a failure's detail printed (a response body or a log can be long)

passed = 0
failed = 0
_show_passes = False
_at_failure = []  # called by finish() before the summary when a check failed (tests/server/harness.py: server logs)


def check(name, condition, detail=""):
    """Counts one named check; prints a failure with its detail. Returns the condition (to stop early on it)."""
    global passed, failed
    if condition:
        passed += 1
        if _show_passes:
            print(f"ok   {name}", flush=True)
    else:
        failed += 1
        detail = str(detail)
        print(f"FAIL {name}" + (f": {detail[:DETAIL_LIMIT]}" if detail else ""), flush=True)
    return condition


def show_passes(on=True):
    """From now on, also print "ok   name" for every check that holds (scripts that list all they checked)."""
    global _show_passes
    _show_passes = on


def at_failure(fn):
    """Registers fn() to run at finish() when a check failed (e.g. to print a server's log). A decorator too."""
    _at_failure.append(fn)
    return fn


def finish():
    """Prints "N passed, M failed" and exits: 1 when a check failed, 0 otherwise."""
    if failed:
        for fn in _at_failure:
            fn()
    print(f"{passed} passed, {failed} failed", flush=True)
    sys.exit(1 if failed else 0)


def skip(reason):
    """Prints "SKIP: reason" and exits 77 (CTest: skipped), or finishes as a failure if a check already failed."""
    print(f"SKIP: {reason}", flush=True)
    if failed:
        finish()
    sys.exit(SKIP)


@contextlib.contextmanager
def section(name, failure=None):
    """A part of a script that may crash: an exception in it is one failed check, named `failure` (by default
    "<name>: the checks ran to the end"), with its traceback printed, and the script goes on after the block.
    Prints the part's time."""
    t0 = time.time()
    try:
        yield
    except Exception as exc:  # a crash of one part is a failure; the other parts still run
        traceback.print_exc()
        check(failure or f"{name}: the checks ran to the end", False, repr(exc))
    print(f"{name}: {time.time() - t0:.1f} s", flush=True)
