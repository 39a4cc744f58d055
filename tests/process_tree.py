"""Finding the processes a test started: every process of a session (Linux ``/proc``).  A test
starts the command under test with ``start_new_session=True``; its session id is then the
command's process id, and every process the command starts (workers, fork servers, resource
trackers) keeps it unless it starts a session of its own."""

import os
import time


def session_processes(sid: int) -> list[int]:
    """Process ids of the live (not zombie) processes of session ``sid``."""
    out = []
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/stat", "rb") as fh:
                stat = fh.read().decode(errors="replace")
        except OSError:  # ended meanwhile
            continue
        fields = stat[stat.rindex(")") + 2 :].split()  # after "pid (comm) "
        state, session = fields[0], int(fields[3])
        if session == sid and state not in ("Z", "X"):
            out.append(int(name))
    return out


def describe(pids) -> str:
    lines = []
    for pid in pids:
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as fh:
                cmd = fh.read().replace(b"\0", b" ").decode(errors="replace")
            lines.append(f"{pid}: {cmd[:200]}")
        except OSError:
            pass
    return "\n".join(lines)


def assert_session_ends(sid: int, within_s: float) -> None:
    """Every process of session ``sid`` has ended within ``within_s`` seconds."""
    end = time.monotonic() + within_s
    while True:
        left = session_processes(sid)
        if not left:
            return
        if time.monotonic() > end:
            raise AssertionError(f"{len(left)} processes still alive {within_s:g} s after the kill:\n{describe(left)}")
        time.sleep(0.5)
