"""Shared by the documentation tests: run the ```python blocks of a docs page."""

import os
import re
import shlex
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1] / "docs"


def run_python_blocks(page: str, cwd=None) -> str:
    """Execute every ```python block of docs/``page`` in order, each in a fresh namespace, in folder
    ``cwd`` (default: the current one); returns the page's text.  Fails if the page has none.

    A block followed by a quoted ``Output:`` (a fenced or indented block) must print those lines,
    number by number (:func:`check_output`), so that quoted output cannot drift."""
    import contextlib
    import io
    import sys

    text = (DOCS / page).read_text()
    blocks = list(re.finditer(r"```python\n(.*?)```", text, re.S))
    assert blocks, f"{page} has no python example"
    old = os.getcwd()
    if cwd is not None:
        os.chdir(cwd)
    try:
        for i, m in enumerate(blocks):
            buf = io.StringIO()
            tee = _Tee(sys.stdout, buf)
            with contextlib.redirect_stdout(tee):
                exec(compile(m.group(1), f"{page}[{i}]", "exec"), {"__name__": "__doc_example__"})
            quoted = quoted_output(text[m.end() :])
            if quoted is not None:
                check_output(quoted, buf.getvalue(), f"{page}, example {i + 1}")
    finally:
        os.chdir(old)
    return text


class _Tee:
    def __init__(self, *streams):
        self.streams = streams

    def write(self, s):
        for st in self.streams:
            st.write(s)
        return len(s)

    def flush(self):
        for st in self.streams:
            st.flush()


def quoted_output(after: str):
    """The lines of the ``Output:`` block that follows a code block (None if none follows)."""
    m = re.match(r"\s*Output:\s*\n\n(?:```\w*\n(.*?)```|((?:    [^\n]*\n|\n)+))", after, re.S)
    if m is None:
        return None
    body = m.group(1) if m.group(1) is not None else "\n".join(ln[4:] for ln in m.group(2).splitlines())
    return [ln for ln in body.strip("\n").splitlines() if ln.strip()]


def check_output(quoted, printed: str, where: str) -> None:
    """Every quoted line is printed, in order, numbers to 3 units of their last quoted digit
    (:func:`_same_line`).  Two allowances, each for a reason: a quoted number below 1e-9 in
    magnitude is round-off (a residual) and only has to stay below 1e-9, since its digits follow
    the order of summation; text after ';' on a line naming a scipy termination condition is
    scipy's own message, which changes between scipy versions."""
    got = [ln for ln in printed.splitlines() if ln.strip()]
    assert len(got) == len(quoted), f"{where}: quotes {len(quoted)} lines of output, the example prints {len(got)}"
    for q, g in zip(quoted, got):
        if "termination condition" in q:
            q, g = q.split(";")[0], g.split(";")[0]
        q2, g2 = _roundoff(q), _roundoff(g)
        assert q2[1] == g2[1] or not q2[1], f"{where}: round-off value above 1e-9 in {g!r}"
        assert _same_line(q2[0].strip(), g2[0].strip()), f"{where}: the page quotes {q!r}, the example prints {g!r}"


def _roundoff(line: str):
    """(line with numbers of magnitude < 1e-9 replaced by '~0', whether there were any and all are < 1e-9)."""
    tiny = []

    def sub(m):
        v = float(m.group(0))
        if v != 0.0 and abs(v) < 1e-9:
            tiny.append(v)
            return "~0"
        return m.group(0)

    return _NUMBER.sub(sub, line), bool(tiny)


_NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def _ulp(token: str) -> float:
    """One unit in the last printed digit of a number as quoted ("8.04317" -> 1e-5, "3.2e-07" -> 1e-8)."""
    mant, _, exp = token.lower().partition("e")
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    return 10.0 ** (int(exp or 0) - decimals)


def _same_line(quoted: str, printed: str) -> bool:
    """``quoted`` equals ``printed`` up to its numbers, which may differ by 3 units in their last
    quoted digit: an FE fit quoted to 6 digits moves in the 6th with round-off in the solver's order
    of summation (session 3), while a wrong value differs by far more.

    A fitted value quoted with its standard error, ``V +- S``, may also move by S / 10: the fits
    stop when the cost changes by less than 1e-4 of itself, and near the minimum a parameter that
    moves by d standard errors changes the cost (chi^2 / 2 of a few hundred residuals) by d^2 / 2,
    so the stopping rule leaves it up to ~0.07 S from the exact minimum; round-off in the FE runs
    decides where within that the fit stops (e.g. ball-joint mu 0.04754 -> 0.04745 +- 0.02)."""
    if _NUMBER.sub("#", quoted) != _NUMBER.sub("#", printed):
        return False
    q, p = _NUMBER.findall(quoted), _NUMBER.findall(printed)
    if len(q) != len(p):
        return False
    tol = [3 * _ulp(a) for a in q]
    for m in re.finditer(r"(" + _NUMBER.pattern + r")\s*\+-\s*(" + _NUMBER.pattern + r")", quoted):
        k = len(_NUMBER.findall(quoted[: m.start()]))  # index of V among the line's numbers
        tol[k] = max(tol[k], 0.1 * abs(float(q[k + 1])))
    return all(abs(float(a) - float(b)) <= t for a, b, t in zip(q, p, tol))


def quoted_in(quoted: str, out: str) -> bool:
    """``quoted`` (a phrase a page says an example prints) occurs in ``out`` with its numbers equal
    to what :func:`_same_line` allows -- never compared as text."""
    parts = _NUMBER.split(quoted)
    nums = _NUMBER.findall(quoted)
    pattern = "".join(
        re.escape(t) + ("(" + _NUMBER.pattern + ")" if i < len(nums) else "") for i, t in enumerate(parts)
    )
    for m in re.finditer(pattern, out):
        if _same_line(quoted, m.group(0)):
            return True
    return False


def _printed(line: str, out: str) -> bool:
    if line in out:
        return True
    core = line.strip()
    return any(core in o or _same_line(core, o.strip()) for o in out.splitlines())


def replay_transcript(
    block: str, folder, capsys, ignore=lambda line: False, what: str = "the page", printed=None
) -> int:
    """Run the commands of a quoted console transcript in ``folder`` (the current directory) --
    ``$ femast ...`` through femast.cli.main, ``$ head -N FILE`` -- and check that every other
    non-blank line (unless ``ignore(line)``) is in what the command before it printed, numbers to 3
    units in their last quoted digit (:func:`_same_line`).  A run time quoted after a command,
    ``(12.3 s)``, is not part of it.  ``printed``: {command line as quoted: what that command printed
    in a run the test has made already} (the same command, perhaps with another ``--out``), not run
    again.  Returns the number of lines checked."""
    from femast.cli import main

    out, checked = "", 0
    for line in block.splitlines():
        if line.startswith("$ "):
            quoted = re.sub(r"\s+\(\d+(\.\d+)? s\)$", "", line[2:])
            cmd = shlex.split(quoted)
            if printed and quoted in printed:
                out = printed[quoted]
            elif cmd[0] == "femast":
                assert main(cmd[1:]) == 0, line
                out = capsys.readouterr().out
            elif cmd[0] == "head":
                out = "".join((Path(folder) / cmd[-1]).read_text().splitlines(True)[: int(cmd[1][1:])])
            continue
        if line.strip() and not ignore(line):
            assert _printed(line.rstrip(), out), f"{what} quotes a line the command does not print:\n{line}"
            checked += 1
    return checked


def assert_same_numbers(quoted: str, printed: str, roundoff: float = 0.0, ulps: float = 1.0) -> None:
    """Assert that line ``printed`` says what ``quoted`` (a docs page's output) says, number by
    number: the same text around the numbers; each number within ``ulps`` units of its last quoted
    digit (a printed value is the true value rounded to that digit, so a round-off change of the
    true value moves it by at most one unit); and a number quoted below ``roundoff`` in magnitude (a
    residual at round-off, whose digits depend on the platform's BLAS and summation order) only
    needs to be below ``roundoff`` too.  Never a comparison of printed floats as text."""
    assert _NUMBER.sub("#", quoted) == _NUMBER.sub("#", printed), f"text differs:\n{quoted}\n{printed}"
    q, p = _NUMBER.findall(quoted), _NUMBER.findall(printed)
    assert len(q) == len(p), f"number count differs:\n{quoted}\n{printed}"
    for a, b in zip(q, p):
        if abs(float(a)) < roundoff:
            assert abs(float(b)) < roundoff, f"{b} is not at round-off (< {roundoff:g}) as quoted {a}:\n{printed}"
        else:
            assert abs(float(a) - float(b)) <= ulps * _ulp(a) * (1 + 1e-9), f"{b} differs from quoted {a}:\n{printed}"


def printed_in(quoted: str, out: str, ulps: float = 3.0) -> bool:
    """True if some line of ``out`` contains ``quoted`` (a fragment a docs page says is printed)
    with the same text around the numbers and each number within ``ulps`` units of its last quoted
    digit (3, as :func:`_same_line`: round-off in the order of summation moves a 6-digit fit in its
    last digit).  Numbers are compared as numbers, never as text."""
    sq = _NUMBER.sub("#", quoted)
    qn = [float(t) for t in _NUMBER.findall(quoted)]
    qu = [_ulp(t) for t in _NUMBER.findall(quoted)]
    for line in out.splitlines():
        tokens = list(_NUMBER.finditer(line))
        sl = _NUMBER.sub("#", line)
        start = sl.find(sq)
        while start >= 0:
            k = sl[:start].count("#")  # numbers of the line before the fragment
            got = [float(m.group()) for m in tokens[k : k + len(qn)]]
            if len(got) == len(qn) and all(abs(a - b) <= ulps * u * (1 + 1e-9) for a, b, u in zip(qn, got, qu)):
                return True
            start = sl.find(sq, start + 1)
    return False
