#!/usr/bin/python3
"""Run the code blocks of FrostMPM's documentation, so the docs stay true.

    /usr/bin/python3 scripts/check_docs.py [--bin build/bin] [FILE.md ...]

Reads README.md, docs/*.md and examples/*/README.md (or the files given) and, for each fenced
code block, in document order:

* ```yaml  A whole scene (a top-level `task:` key, or grid, time, physics, materials and
           regions) is written to a file and validated with `frostmpm check FILE` (exit 0
           expected). Any other YAML block is parsed (PyYAML; skipped when it is missing).
* ```sh / ```bash  Each command line (`\\` continuations joined, `&&` chains split) runs
           with bash from a scratch copy of the repository root (its files copied into a
           temporary folder, one per document), so `out/...`, saved scenes and regenerated
           figures land there and nothing in the repository is written. `./build/bin/X` and a bare
           `frostmpm` are the programs of --bin. Every command must exit 0 within
           --max-seconds. Commands the build itself provides (`bash scripts/setup-debian.sh`,
           `scripts/build.sh`, `scripts/test.sh`) are not run, nor is `frostmpm run --restart`
           (it needs a run stopped half-way).
* ```python  Runs with this Python from the same folder (the results of the blocks above).

Blocks without a language, and cpp/cmake blocks, are not checked. An HTML comment on the
line(s) right before a block steers it:

    <!-- docs-check: skip (reason) -->   not run (a long run, a build, a plugin built first);
                                         its `frostmpm run SCENE ...` lines are still validated
                                         with `frostmpm check SCENE ...` where the scene exists
                                         and no extra plugin is needed; YAML is still parsed
    <!-- docs-check: save NAME -->       a YAML block is also saved as NAME in the scratch
                                         root, for the commands after it ("save it as NAME")

--run-skipped also runs the skipped blocks, each command capped at --max-seconds: a command
still running then is stopped and counted as "capped", not as a failure.

Prints what ran, what was checked and what was skipped, then one line per failure naming the
document and line; exits 1 on any failure, 2 on bad usage. Uses the standard library only
(PyYAML optional).
"""

import argparse
import importlib.util
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field

try:
    import yaml  # Debian: python3-yaml
except ImportError:  # pragma: no cover
    yaml = None

FENCE = re.compile(r"^(?P<indent>[ \t]*)(?P<fence>```+|~~~+)\s*(?P<info>[^`\s]*)[^`]*$")
MARKER = re.compile(r"^\s*<!--\s*docs-check:\s*(?P<body>.*?)\s*-->\s*$")
SHELL_LANGS = {"sh", "bash", "shell", "console"}
YAML_LANGS = {"yaml", "yml"}
PYTHON_LANGS = {"python", "py", "python3"}
SCENE_SECTIONS = {"grid", "time", "physics", "materials", "regions"}
# Commands the build and CI provide; a docs check does not rerun them.
PROVIDED = {
    ("bash", "scripts/setup-debian.sh"): "installs system packages (the CI image has them)",
    ("bash", "scripts/build.sh"): "the build (already done: --bin)",
    ("bash", "scripts/test.sh"): "the whole test suite (ctest runs it)",
}
# Programs a command may start with; anything else must sit in a skipped block.
RUNNABLE_PYTHON_DIRS = ("scripts/", "bench/")


@dataclass
class Block:
    doc: str
    line: int  # line of the opening fence (1-based)
    lang: str
    text: str
    skip: str | None = None
    save: str | None = None
    bad_markers: list = field(default_factory=list)


@dataclass
class Report:
    ran: list = field(default_factory=list)
    checked: list = field(default_factory=list)
    skipped: list = field(default_factory=list)
    capped: list = field(default_factory=list)
    failed: list = field(default_factory=list)


def parse_blocks(path, rel):
    """Fenced code blocks of one Markdown file, with their docs-check markers."""
    lines = open(path, encoding="utf-8").read().split("\n")
    blocks, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence, info = m.group("indent"), m.group("fence"), m.group("info").lower()
        start = i
        body = []
        i += 1
        while i < len(lines) and not (lines[i].strip().startswith(fence) and lines[i].strip().strip(fence[0]) == ""):
            body.append(lines[i][len(indent):] if lines[i].startswith(indent) else lines[i].lstrip())
            i += 1
        i += 1  # closing fence
        block = Block(rel, start + 1, info, "\n".join(body))
        j = start - 1
        while j >= 0 and MARKER.match(lines[j]):
            words = MARKER.match(lines[j]).group("body")
            if words.startswith("skip"):
                reason = words[4:].strip()
                block.skip = reason[1:-1] if reason.startswith("(") and reason.endswith(")") else (reason or "no reason given")
            elif words.startswith("save "):
                block.save = words[5:].strip()
            else:
                block.bad_markers.append((j + 1, words))
            j -= 1
        blocks.append(block)
    return blocks


def command_lines(block):
    """(line number, command) for each command of a shell block: continuations joined."""
    out, pending, first = [], "", None
    for k, raw in enumerate(block.text.split("\n")):
        line = raw.rstrip()
        if not pending and (not line.strip() or line.lstrip().startswith("#")):
            continue
        if line.startswith("$ "):
            line = line[2:]
        if first is None:
            first = block.line + 1 + k
        if line.endswith("\\"):
            pending += line[:-1] + " "
            continue
        out.append((first, pending + line))
        pending, first = "", None
    if pending:
        out.append((first, pending))
    return out


def split_chain(cmd):
    """Split a command at top-level `&&` (quotes respected); return the parts as text."""
    parts, cur, quote, k = [], "", None, 0
    while k < len(cmd):
        c = cmd[k]
        if quote:
            cur += c
            if c == quote:
                quote = None
            elif c == "\\" and quote == '"' and k + 1 < len(cmd):
                cur += cmd[k + 1]
                k += 1
        elif c in "'\"":
            quote = c
            cur += c
        elif c == "#" and (not cur or cur[-1].isspace()):
            break  # comment to the end of the line
        elif cmd.startswith("&&", k):
            parts.append(cur.strip())
            cur = ""
            k += 1
        else:
            cur += c
        k += 1
    parts.append(cur.strip())
    return [p for p in parts if p]


def words_of(cmd):
    try:
        return shlex.split(cmd, comments=True)
    except ValueError:
        return cmd.split()


def program_words(words):
    """The words after leading VAR=value assignments."""
    k = 0
    while k < len(words) and re.match(r"^[A-Za-z_][A-Za-z0-9_]*=", words[k]):
        k += 1
    return words[k:], words[:k]


def is_frostmpm(word):
    return word in ("frostmpm", "./build/bin/frostmpm", "build/bin/frostmpm")


def classify(cmd):
    """('provided', reason) | ('restart', None) | ('run', None) | ('frostmpm', None) |
    ('bin', None) | ('python', None) | ('unknown', None)."""
    words, env = program_words(words_of(cmd))
    if not words:
        return "unknown", None
    key = tuple(words[:2])
    if key in PROVIDED:
        return "provided", PROVIDED[key]
    if is_frostmpm(words[0]):
        if len(words) > 1 and words[1] == "run":
            return ("restart", None) if "--restart" in words else ("run", None)
        return "frostmpm", None
    if words[0].startswith("./build/bin/") or words[0].startswith("build/bin/"):
        return "bin", None
    if words[0] in ("/usr/bin/python3", "python3") and len(words) > 1 and words[1].startswith(RUNNABLE_PYTHON_DIRS):
        return "python", None
    return "unknown", None


def as_check(cmd, root):
    """`frostmpm run SCENE [--set ...]` as `frostmpm check SCENE [--set ...]`, or None when that
    cannot stand for it here (a plugin built first, a scene that is not there)."""
    words, env = program_words(words_of(cmd))
    if any(w.startswith("FROSTMPM_PLUGIN_PATH=") for w in env) or "--plugin-path" in words:
        return None
    keep, k, scene = [], 2, None
    while k < len(words):
        w = words[k]
        if w in ("-o", "--output", "--threads"):
            k += 2
            continue
        if w in ("--overwrite", "-q", "--quiet", "-v", "--verbose"):
            k += 1
            continue
        if w == "--set" and k + 1 < len(words):
            keep += [w, words[k + 1]]
            k += 2
            continue
        if w in ("|", ">", "2>&1"):
            break
        if scene is None and not w.startswith("-"):
            scene = w
        keep.append(w)
        k += 1
    if scene is None or not os.path.isfile(os.path.join(root, scene)):
        return None
    return " ".join(shlex.quote(w) for w in [words[0], "check"] + keep)


def is_scene(data):
    if not isinstance(data, dict):
        return False
    return "task" in data or SCENE_SECTIONS <= set(data)


def looks_like_scene(text):
    """Without PyYAML: top-level keys of the block."""
    keys = set(re.findall(r"^([A-Za-z_]+):", text, flags=re.M))
    return "task" in keys or SCENE_SECTIONS <= keys


class Runner:
    def __init__(self, args, repo):
        self.args = args
        self.repo = repo
        self.bin = args.bin
        self.report = Report()
        self.env = dict(os.environ)
        self.env["PATH"] = self.bin + os.pathsep + self.env.get("PATH", "")
        self.env.pop("FROSTMPM_PLUGIN_PATH", None)
        self.env["PYTHONDONTWRITEBYTECODE"] = "1"

    def scratch_root(self):
        """A copy of the repository's files (tracked and untracked, not ignored; no build, no
        .git) with build/bin the programs under test: commands write into it, never into the
        repository (a doc may regenerate a figure or a table in place)."""
        root = tempfile.mkdtemp(prefix="frostmpm-docs-")
        try:
            listed = subprocess.run(["git", "-C", self.repo, "ls-files", "-z", "--cached", "--others",
                                     "--exclude-standard"], capture_output=True, check=True).stdout
            names = [n for n in listed.decode().split("\0") if n]
        except (OSError, subprocess.CalledProcessError):
            names = []
            for top, dirs, files in os.walk(self.repo):
                dirs[:] = [d for d in dirs if not d.startswith(".") and not (top == self.repo and d in ("build", "out"))]
                names += [os.path.relpath(os.path.join(top, f), self.repo) for f in files]
        for name in names:
            src = os.path.join(self.repo, name)
            if not os.path.isfile(src) or name.split("/")[0] in ("build", "out"):
                continue
            dst = os.path.join(root, name)
            os.makedirs(os.path.dirname(dst), exist_ok=True)
            shutil.copy2(src, dst)
        os.makedirs(os.path.join(root, "build"))
        os.symlink(self.bin, os.path.join(root, "build", "bin"))
        # What lies beside the programs (plugins, test fixtures), for examples that name it.
        build = os.path.dirname(self.bin)
        if os.path.basename(self.bin) == "bin" and os.path.isdir(build):
            for name in os.listdir(build):
                if not os.path.exists(os.path.join(root, "build", name)):
                    os.symlink(os.path.join(build, name), os.path.join(root, "build", name))
        return root

    def execute(self, cmd, cwd, capped_ok=False):
        """Run one command with bash; returns (status, seconds, first error line)."""
        t0 = time.monotonic()
        proc = subprocess.Popen(["bash", "-o", "pipefail", "-c", cmd], cwd=cwd, env=self.env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                start_new_session=True)
        try:
            out, err = proc.communicate(timeout=self.args.max_seconds)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGTERM)
            try:
                out, err = proc.communicate(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                out, err = proc.communicate()
            secs = time.monotonic() - t0
            return ("capped" if capped_ok else "timeout"), secs, f"still running after {self.args.max_seconds:g} s"
        secs = time.monotonic() - t0
        if self.args.verbose:
            sys.stdout.write(out)
            sys.stderr.write(err)
        if proc.returncode == 0:
            return "ok", secs, ""
        lines = [l for l in (err + "\n" + out).split("\n") if l.strip()]
        errors = [l for l in lines if l.startswith("error") or "Error" in l]
        detail = (errors[0] if errors else lines[-1] if lines else "").strip()
        return f"exit {proc.returncode}", secs, detail

    def fail(self, where, what, detail):
        self.report.failed.append(f"{where}: {what}{': ' + detail if detail else ''}")

    def run_command(self, where, cmd, cwd, skipped_reason):
        kind, why = classify(cmd)
        short = cmd if len(cmd) <= 110 else cmd[:107] + "..."
        if kind == "provided":
            self.report.skipped.append(f"{where}: {short}  [{why}]")
            return
        if kind == "restart":  # in a fresh folder there is no stopped run to continue
            self.report.skipped.append(f"{where}: {short}  [needs a run stopped half-way]")
            return
        if skipped_reason and not self.args.run_skipped:
            check = as_check(cmd, cwd) if kind == "run" else None
            if check:
                status, secs, detail = self.execute(check, cwd)
                if status == "ok":
                    self.report.checked.append(f"{where}: {short}  [skipped: {skipped_reason}; scene checked, {secs:.1f} s]")
                else:
                    self.fail(where, f"`{check}` {status}", detail)
            else:
                self.report.skipped.append(f"{where}: {short}  [{skipped_reason}]")
            return
        if kind == "unknown":  # never run, not even with --run-skipped (cmake, cp, export, ...)
            if skipped_reason:
                self.report.skipped.append(f"{where}: {short}  [{skipped_reason}]")
            else:
                self.fail(where, f"`{short}` is not a command this check runs",
                          "mark its block <!-- docs-check: skip (reason) -->")
            return
        status, secs, detail = self.execute(cmd, cwd, capped_ok=bool(skipped_reason))
        if status == "ok":
            self.report.ran.append(f"{where}: {short}  [{secs:.1f} s]")
        elif status == "capped":
            self.report.capped.append(f"{where}: {short}  [stopped after {secs:.0f} s]")
        elif status == "timeout":
            self.fail(where, f"`{short}` took longer than {self.args.max_seconds:g} s",
                      "mark its block <!-- docs-check: skip (reason) --> or shorten it")
        else:
            self.fail(where, f"`{short}` {status}", detail)

    def yaml_block(self, block, root):
        where = f"{block.doc}:{block.line}"
        if yaml is not None:
            try:
                data = yaml.safe_load(block.text)
            except yaml.YAMLError as e:
                mark = getattr(e, "problem_mark", None)
                line = block.line + 1 + mark.line if mark else block.line
                self.fail(f"{block.doc}:{line}", "YAML does not parse", str(e).split("\n")[0])
                return
            scene = is_scene(data)
        else:
            scene = looks_like_scene(block.text)
        if block.save:
            target = os.path.join(root, block.save)
            os.makedirs(os.path.dirname(target), exist_ok=True)
            with open(target, "w", encoding="utf-8") as f:
                f.write(block.text + "\n")
        if not scene:
            if yaml is None:
                self.report.skipped.append(f"{where}: YAML fragment  [PyYAML missing: not parsed]")
            else:
                self.report.checked.append(f"{where}: YAML fragment parsed")
            return
        if block.skip and not self.args.run_skipped:
            self.report.skipped.append(f"{where}: scene  [{block.skip}]" + (" (parsed)" if yaml else ""))
            return
        if block.save:
            path = block.save
        else:
            path = os.path.relpath(self.scratch_file(block, root, "yaml"), root)
        status, secs, detail = self.execute(f"frostmpm check {shlex.quote(path)}", root,
                                            capped_ok=bool(block.skip))
        if status == "ok":
            self.report.checked.append(f"{where}: scene, frostmpm check {path}  [{secs:.1f} s]")
        else:
            at = re.search(re.escape(os.path.basename(path)) + r":(\d+):\d+", detail)
            line = block.line + int(at.group(1)) if at else block.line  # the scene's line in the doc
            self.fail(f"{block.doc}:{line}", f"scene fails `frostmpm check` ({status})", detail)

    @staticmethod
    def scratch_file(block, root, extension):
        """Writes the block's text to ROOT/.docs-check/<doc>-<line>.<extension>; returns the path."""
        path = os.path.join(root, ".docs-check", f"{os.path.basename(block.doc)}-{block.line}.{extension}")
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w", encoding="utf-8") as f:
            f.write(block.text + "\n")
        return path

    def python_block(self, block, root):
        where = f"{block.doc}:{block.line}"
        if block.skip and not self.args.run_skipped:
            self.report.skipped.append(f"{where}: python block  [{block.skip}]")
            return
        imported = re.findall(r"^\s*(?:import|from)\s+([A-Za-z_][A-Za-z0-9_]*)", block.text, flags=re.M)
        missing = sorted({m for m in imported if importlib.util.find_spec(m) is None})
        if missing:
            self.report.skipped.append(f"{where}: python block  [{sys.executable} lacks {', '.join(missing)}]")
            return
        path = self.scratch_file(block, root, "py")
        status, secs, detail = self.execute(f"{shlex.quote(sys.executable)} {shlex.quote(path)}", root,
                                            capped_ok=bool(block.skip))
        if status == "ok":
            self.report.ran.append(f"{where}: python block  [{secs:.1f} s]")
        else:
            self.fail(where, f"python block {status}", detail)

    def check_doc(self, path):
        rel = os.path.relpath(path, self.repo)
        if rel.startswith(".."):
            rel = path
        root = self.scratch_root()
        try:
            for block in parse_blocks(path, rel):
                for line, words in block.bad_markers:
                    self.fail(f"{rel}:{line}", f"unknown docs-check marker '{words}'",
                              "use 'skip (reason)' or 'save NAME'")
                if block.lang in YAML_LANGS:
                    self.yaml_block(block, root)
                elif block.lang in SHELL_LANGS:
                    for line, cmd in command_lines(block):
                        for part in split_chain(cmd):
                            self.run_command(f"{rel}:{line}", part, root, block.skip)
                elif block.lang in PYTHON_LANGS:
                    self.python_block(block, root)
        finally:
            if self.args.keep:
                print(f"scratch root of {rel}: {root}")
            else:
                shutil.rmtree(root, ignore_errors=True)


def main():
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="*", help="Markdown files (default: README.md, docs/*.md, examples/*/README.md)")
    ap.add_argument("--bin", default="build/bin", help="folder of the frostmpm program (default: build/bin, from the repository root)")
    ap.add_argument("--max-seconds", type=float, default=60, help="wall-time cap of each command (default 60)")
    ap.add_argument("--run-skipped", action="store_true", help="also run blocks marked skip, each command capped at --max-seconds")
    ap.add_argument("--keep", action="store_true", help="keep the scratch folders and print where they are")
    ap.add_argument("-v", "--verbose", action="store_true", help="show the output of every command")
    args = ap.parse_args()

    binary = args.bin if os.path.isabs(args.bin) else os.path.join(repo, args.bin)
    if not os.path.isdir(binary) and os.path.isdir(os.path.abspath(args.bin)):
        binary = os.path.abspath(args.bin)
    args.bin = os.path.realpath(binary)
    if not os.access(os.path.join(args.bin, "frostmpm"), os.X_OK):
        print(f"check_docs: no frostmpm program in {args.bin} (give --bin)", file=sys.stderr)
        return 2

    if args.files:
        files = [os.path.abspath(f) for f in args.files]
    else:
        files = [os.path.join(repo, "README.md")]
        files += sorted(os.path.join(repo, "docs", f) for f in os.listdir(os.path.join(repo, "docs")) if f.endswith(".md"))
        examples = os.path.join(repo, "examples")
        files += sorted(os.path.join(examples, d, "README.md") for d in os.listdir(examples)
                        if os.path.isfile(os.path.join(examples, d, "README.md")))

    t0 = time.monotonic()
    runner = Runner(args, repo)
    for f in files:
        runner.check_doc(f)
    r = runner.report
    for title, items in (("ran", r.ran), ("checked", r.checked), ("capped (--run-skipped)", r.capped), ("skipped", r.skipped)):
        print(f"{title}: {len(items)}")
        for item in items:
            print(f"  {item}")
    if yaml is None:
        print("note: PyYAML is missing; YAML fragments were not parsed")
    secs = time.monotonic() - t0
    if r.failed:
        print(f"FAILED: {len(r.failed)}")
        for item in r.failed:
            print(f"  {item}")
        print(f"check_docs: {len(r.failed)} failure(s) in {secs:.0f} s")
        return 1
    print(f"check_docs: all documentation snippets pass ({len(r.ran)} ran, {len(r.checked)} checked, "
          f"{len(r.skipped)} skipped) in {secs:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
