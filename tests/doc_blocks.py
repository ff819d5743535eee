"""The code blocks of README.md and docs/*.md, and running them as a user would: in an empty folder, with
nothing but an installed gearsym (model names resolve to the installed models).

A fenced block is run if its language is ``bash`` or ``python``. A block that is not meant to run carries a
visible marker in the comment lines right before its fence, with the reason:

    <!-- not run: the clone's set-up; CI runs it (.ci/run) -->

and an output listing says which command prints it; the listing's lines must appear, in order, in what that
command prints when it runs after the page's blocks before it:

    <!-- output of: gearsym modes planetary -->

A ``bash`` block that shows again commands a page of the docs runs (the README's overview of a verb whose page
explains it) names that page, and is not run a second time: each of its commands must be, word for word, a
command of a block that runs on one of the pages named (``tests/test_doc_examples.py`` checks it):

    <!-- runs in: docs/orbits.md -->

A ``mermaid`` diagram needs no marker; any other fence (untagged, ``text``, ...) needs one of the two, so that
no command hides in a block nobody runs. Each page's blocks run in order in one folder of their own (a
command may use the file an earlier block wrote, as a reader following the page would).
"""
from __future__ import annotations

import os
import re
import shlex
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import same_numbers

REPO = Path(__file__).resolve().parents[1]
RUN = ("bash", "python")
DIAGRAMS = ("mermaid",)
_FENCE = re.compile(r"^(?P<indent>[ \t]*)```(?P<language>[\w-]*)[ \t]*\n(?P<body>.*?)^(?P=indent)```[ \t]*$",
                    re.S | re.M)
_MARKER = re.compile(r"<!--\s*(not run|output of|runs in):\s*(.*?)\s*-->")


@dataclass
class Block:
    page: str  # README.md, docs/units.md, ...
    line: int  # of the opening fence
    language: str
    code: str
    not_run: str | None = None  # the reason given
    output_of: str | None = None  # the command whose output the block lists
    runs_in: str | None = None  # the pages whose blocks run its commands (comma-separated)

    @property
    def name(self) -> str:
        return f"{self.page}:{self.line}"

    @property
    def runs(self) -> bool:
        return self.language in RUN and self.not_run is None and self.output_of is None and self.runs_in is None

    @property
    def commands(self) -> list[str]:
        """The block's commands as one line each: continuation lines joined, comments and spacing dropped."""
        return commands(self.code)


def pages() -> list[Path]:
    """README.md and every docs/*.md (pages added later are picked up)."""
    return [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]


def blocks(page: Path) -> list[Block]:
    text = page.read_text(encoding="utf-8")
    name = str(page.relative_to(REPO))
    out = []
    for m in _FENCE.finditer(text):
        before = text[:m.start()].rstrip("\n").split("\n")
        comments = []
        while before and before[-1].strip().startswith("<!--"):
            comments.append(before.pop())
        markers = dict((kind, what) for c in comments for kind, what in _MARKER.findall(c))
        indent = m.group("indent")
        code = "\n".join(line[len(indent):] if line.startswith(indent) else line
                         for line in m.group("body").split("\n"))
        out.append(Block(name, text[:m.start()].count("\n") + 1, m.group("language"), code,
                         markers.get("not run"), markers.get("output of"), markers.get("runs in")))
    return out


def commands(code: str) -> list[str]:
    """The shell commands of ``code``, each as one line (see ``Block.commands``)."""
    joined = re.sub(r"\\\n\s*", " ", code)
    found = []
    for line in joined.split("\n"):
        words = shlex.split(line, comments=True)
        if words:
            found.append(shlex.join(words))
    return found


def unmarked(block: Block) -> str | None:
    """Why a block breaks the rules above (None if it keeps them)."""
    if block.not_run is not None and not block.not_run.strip():
        return "a 'not run' marker without its reason"
    if block.runs_in is not None and block.language != "bash":
        return "a 'runs in' marker on a block that is not ```bash (only shell commands are looked up on a page)"
    if block.language in RUN or block.language in DIAGRAMS:
        return None
    if block.not_run is None and block.output_of is None:
        return (f"a ```{block.language or '(untagged)'} block: tag a command ```bash or ```python so that it runs, or "
                "mark it <!-- not run: why --> or <!-- output of: COMMAND -->")
    return None


@dataclass
class Ran:
    block: Block
    status: int
    seconds: float
    output: str = ""
    listing_missing: list[str] = field(default_factory=list)
    cpu: float = 0.0


#: what the user's environment does not have: nothing of the clone importable but the installed package, no
#: test of pytest's running, and Python's bytecode cache as a user's Python keeps it (a machine that turns it off
#: has every command compile the hundred-odd modules of gearsym it imports from source again: 0.3 s each)
NOT_THE_USERS = ("PYTHONPATH", "PYTEST_CURRENT_TEST", "PYTHONDONTWRITEBYTECODE")


def environment() -> dict:
    """The user's environment: gearsym's command on the PATH, the session's library cache, none of
    :data:`NOT_THE_USERS`, matplotlib without a display."""
    env = {k: v for k, v in os.environ.items() if k not in NOT_THE_USERS}
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    env["MPLBACKEND"] = "Agg"
    return env


def run_block(block: Block, folder: Path, env: dict, timeout: float = 900) -> tuple[int, str, float]:
    if block.language == "python":
        argv = [sys.executable, "-c", block.code]
    else:
        argv = ["bash", "-e", "-o", "pipefail", "-c", block.code]
    t0 = time.perf_counter()
    # a session of its own: on a timeout the block's commands are ended with it (none is left running)
    with subprocess.Popen(argv, cwd=folder, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          start_new_session=True) as process:
        try:
            output, _ = process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:  # (a failure of this block, said as such: the page stops here)
            os.killpg(process.pid, signal.SIGKILL)
            output, _ = process.communicate()
            return 124, f"{output}\n[timed out after {timeout:g} s]", time.perf_counter() - t0
    return process.returncode, output, time.perf_counter() - t0


def cpu_seconds() -> float:
    """CPU time of this process's finished children (for measuring the blocks)."""
    import resource
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def listing_missing(listing: str, output: str) -> list[str]:
    """The lines of ``listing`` that ``output`` lacks, in order (whitespace runs compared as one space, numbers as
    numbers: another CPU may print the last digit one unit away, see ``same_numbers``)."""
    def norm(line: str) -> str:
        return " ".join(line.split())
    lines = [norm(x) for x in output.splitlines()]
    missing, at = [], 0
    for want in (norm(x) for x in listing.splitlines() if x.strip()):
        found = next((i for i in range(at, len(lines)) if not same_numbers.differences(lines[i], want)), None)
        if found is None:
            missing.append(want)
        else:
            at = found + 1
    return missing


def run_page(page: Path, scratch: Path) -> list[Ran]:
    """Every block of ``page`` that runs, in order, in a folder of its own under ``scratch``."""
    folder = scratch / page.stem
    folder.mkdir(parents=True)
    env = environment()
    ran = []
    for block in blocks(page):
        if block.runs:
            cpu = cpu_seconds()
            status, output, seconds = run_block(block, folder, env)
            ran.append(Ran(block, status, seconds, output, cpu=cpu_seconds() - cpu))
            if status:
                break  # the rest of the page may need what this block should have made
        elif block.output_of is not None:
            status, output, seconds = run_block(Block(block.page, block.line, "bash", block.output_of), folder, env)
            ran.append(Ran(block, status, seconds, output, listing_missing(block.code, output)))
    return ran


if __name__ == "__main__":  # python tests/doc_blocks.py [PAGE ...]: run pages and time their blocks
    import tempfile

    chosen = [REPO / p for p in sys.argv[1:]] or pages()
    with tempfile.TemporaryDirectory() as scratch:
        for page in chosen:
            cpu = cpu_seconds()
            for r in run_page(page, Path(scratch)):
                print(f"{r.seconds:7.1f} s ({r.cpu:6.1f} s CPU)  status {r.status}  {r.block.name}  "
                      f"{r.block.code.splitlines()[0][:70]}", flush=True)
                if r.status or r.listing_missing:
                    print(r.output[-3000:], r.listing_missing)
            print(f"{page.name}: {cpu_seconds() - cpu:.1f} s CPU", flush=True)
    print(shlex.join(sys.argv))
