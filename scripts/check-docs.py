#!/usr/bin/env python3
"""Runs every ```sh block of the Markdown docs and reports file:line of each failing command.

The convention (docs/development.md, "Commands in the docs"):
  - a block fenced ```sh must run as written from the repository root after
    `bash scripts/quickstart.sh`;
  - ```text / ```console (and other languages: cpp, json) are illustrative and never run; a block
    without a tag is an error, so that a command cannot escape the check by accident;
  - a line `<!-- no-check: REASON -->` right before a ```sh fence skips that block (a reason is
    required).

Each block runs in one bash process (so `P=...` carries to the next command of the block), inside
a sandbox: a fresh temporary folder `repo/` whose entries are symlinks to the repository's (except
`build`, which points at --build, and `out/`, an empty real folder) next to `shared` -> the shared
data folder, so `./build/tools/pushgraph`, `data/...`, `../shared/...` resolve as the docs assume
and every output lands in the temporary folder. Blocks of one file run in order in the same
sandbox (a block may use files an earlier block of the same file wrote); each file gets its own.
Each command has its own time limit; on a failure or time-out the rest of its block is skipped.

Usage: check-docs.py --repo DIR --build DIR [--shared DIR] [--timeout S] [--list] [FILE.md...]
Exit status: 0 all passed, 1 a command failed, 2 bad usage or a bad no-check marker.
"""
import argparse
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

FENCE = re.compile(r"^(\s*)(```+|~~~+)\s*([A-Za-z0-9_+-]*)")
NO_CHECK = re.compile(r"^\s*<!--\s*no-check\b\s*:?\s*(.*?)\s*-->\s*$")


class Block:
    def __init__(self, path, fence_line, no_check_reason):
        self.path = path
        self.fence_line = fence_line  # 1-based line of the opening fence
        self.no_check_reason = no_check_reason
        self.lines = []  # (line number, text)


def read_sh_blocks(path):
    """The ```sh blocks of one Markdown file, each with its no-check reason (None: checked)."""
    blocks, problems = [], []
    with open(path, encoding="utf-8") as f:
        text = f.read().splitlines()
    i = 0
    previous_nonblank = ""
    while i < len(text):
        m = FENCE.match(text[i])
        if not m:
            if text[i].strip():
                previous_nonblank = text[i]
            i += 1
            continue
        fence, tag = m.group(2), m.group(3).lower()
        marker = NO_CHECK.match(previous_nonblank)
        block = None
        if tag == "sh":
            reason = None
            if marker:
                reason = marker.group(1)
                if not reason:
                    problems.append("%s:%d: no-check marker without a reason" % (path, i))
            block = Block(path, i + 1, reason)
        elif marker:
            problems.append("%s:%d: no-check marker before a block that is not ```sh" % (path, i + 1))
        elif not tag:
            # An untagged block would silently escape the check: say what it is.
            problems.append("%s:%d: code block without a language tag: ```sh (runs in the check), "
                            "```text or ```console (never runs)" % (path, i + 1))
        i += 1
        while i < len(text) and not text[i].strip().startswith(fence[0] * len(fence)):
            if block is not None:
                block.lines.append((i + 1, text[i]))
            i += 1
        if block is not None:
            blocks.append(block)
        previous_nonblank = ""
        i += 1
    return blocks, problems


def is_complete(source):
    """True when bash parses `source` as complete commands (no open quote, \\, heredoc, if ...)."""
    r = subprocess.run(["bash", "-n"], input=source, text=True, capture_output=True)
    return r.returncode == 0


def split_commands(block):
    """Groups a block's lines into commands: [(first line number, source)]; comment-only and
    blank lines are dropped. A command ends at the first line where bash can parse it whole."""
    commands, pending, start = [], [], None
    for number, line in block.lines:
        if not pending and (not line.strip() or line.lstrip().startswith("#")):
            continue
        if not pending:
            start = number
        pending.append(line)
        source = "\n".join(pending)
        if not source.rstrip().endswith("\\") and is_complete(source + "\n"):
            commands.append((start, source))
            pending = []
    if pending:
        commands.append((start, "\n".join(pending)))  # bash reports the syntax error when it runs
    return commands


def make_sandbox(root, repo, build, shared):
    work = os.path.join(root, "repo")
    os.makedirs(os.path.join(work, "out"))
    for name in os.listdir(repo):
        if name in ("out", ".git") or name == "build" or name.startswith("build-"):
            continue
        os.symlink(os.path.join(repo, name), os.path.join(work, name))
    os.symlink(build, os.path.join(work, "build"))
    if shared and os.path.isdir(shared):
        os.symlink(shared, os.path.join(root, "shared"))
    return work


def block_script(commands, state):
    """One bash script for a block: before each command it records the command's line in
    `state/current`; each command's stdout and stderr go to `state/<line>.out|.err`. A { } group
    (not a subshell) keeps variable assignments and cd for the next command."""
    parts = ["set -o pipefail", "cd \"$PG_DOCS_WORK\""]
    for line, source in commands:
        parts.append("echo %d > '%s/current'" % (line, state))
        parts.append("{\n%s\n} > '%s/%d.out' 2> '%s/%d.err'" % (source, state, line, state, line))
        parts.append("rc=$?; if [ $rc -ne 0 ]; then echo %d $rc > '%s/failed'; exit 1; fi"
                     % (line, state))
    parts.append("echo done > '%s/current'" % state)
    return "\n".join(parts) + "\n"


def tail(path, lines=25):
    try:
        with open(path, errors="replace") as f:
            content = f.read().splitlines()
    except OSError:
        return ""
    if len(content) > lines:
        content = ["... (%d lines before)" % (len(content) - lines)] + content[-lines:]
    return "\n".join("    | " + l for l in content)


def run_block(block, commands, work, state, timeout):
    """Runs one block; returns None on success or (line, message) for the failing command."""
    os.makedirs(state, exist_ok=True)
    script = os.path.join(state, "block.sh")
    with open(script, "w") as f:
        f.write(block_script(commands, state))
    # The checker's own settings are not the user's: a command in the docs sees the defaults.
    env = {k: v for k, v in os.environ.items() if k not in ("BUILD_DIR", "SHARED_DIR", "DOCS_TIMEOUT")}
    env["PG_DOCS_WORK"] = work
    shell_log = os.path.join(state, "shell.err")  # a file, not a pipe: cannot fill up and block
    with open(shell_log, "w") as log:
        proc = subprocess.Popen(["bash", script], cwd=work, env=env, stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=log, start_new_session=True)
    current, started = None, time.monotonic()
    while True:
        try:
            proc.wait(timeout=0.2)
            break
        except subprocess.TimeoutExpired:
            pass
        try:
            with open(os.path.join(state, "current")) as f:
                now = f.read().strip()
        except OSError:
            now = None
        if now != current:
            current, started = now, time.monotonic()
        elif current and current != "done" and time.monotonic() - started > timeout:
            os.killpg(proc.pid, signal.SIGKILL)  # the block's own session: the command and its children
            proc.wait()
            line = int(current)
            return line, "timed out after %g s\n%s" % (timeout, tail(os.path.join(state, "%d.err" % line)))
    shell_err = tail(shell_log)
    failed = os.path.join(state, "failed")
    if os.path.exists(failed):
        with open(failed) as f:
            line, rc = f.read().split()
        line = int(line)
        message = "exit status %s" % rc
        err = tail(os.path.join(state, "%d.err" % line))
        if not err:
            message += " (no stderr; stdout:)\n" + tail(os.path.join(state, "%d.out" % line))
        return line, message + ("\n" + err if err else "")
    if proc.returncode != 0:
        return block.fence_line, "the block's shell failed (status %d)\n%s" % (proc.returncode, shell_err)
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repo", required=True, help="repository root")
    parser.add_argument("--build", required=True, help="build folder that `build` stands for")
    parser.add_argument("--shared", help="shared data folder that ../shared stands for "
                        "(default: REPO/../shared)")
    parser.add_argument("--timeout", type=float, default=300, help="seconds per command")
    parser.add_argument("--list", action="store_true", help="list the commands, run nothing")
    parser.add_argument("--keep", action="store_true", help="keep the sandbox (its path is printed)")
    parser.add_argument("files", nargs="*", help="Markdown files (default: README.md docs/*.md)")
    args = parser.parse_args()

    repo = os.path.realpath(args.repo)
    build = os.path.realpath(args.build)
    shared = os.path.realpath(args.shared or os.path.join(repo, "..", "shared"))
    files = args.files or ["README.md"] + sorted(
        os.path.join("docs", n) for n in os.listdir(os.path.join(repo, "docs")) if n.endswith(".md"))
    if not os.path.exists(os.path.join(build, "tools", "pushgraph")):
        print("check-docs: no tool at %s/tools/pushgraph; build the target pushgraph first" % build,
              file=sys.stderr)
        return 2

    all_problems, plan = [], []
    for name in files:
        path = name if os.path.isabs(name) else os.path.join(repo, name)
        blocks, problems = read_sh_blocks(path)
        all_problems += [p.replace(repo + os.sep, "") for p in problems]
        plan.append((os.path.relpath(path, repo), blocks))
    for p in all_problems:
        print(p)
    if all_problems:
        return 2

    root = tempfile.mkdtemp(prefix="pushgraph-docs-")
    failures, ran, skipped = [], 0, 0
    try:
        for rel, blocks in plan:
            work = None
            for k, block in enumerate(blocks):
                if block.no_check_reason is not None:
                    skipped += 1
                    print("skip %s:%d (no-check: %s)" % (rel, block.fence_line, block.no_check_reason))
                    continue
                if not os.path.isdir(shared) and any("../shared" in l for _, l in block.lines):
                    skipped += 1  # a clone without the shared MIT sample beside it
                    print("skip %s:%d (no shared data at %s)" % (rel, block.fence_line, shared))
                    continue
                commands = split_commands(block)
                if args.list:
                    for line, source in commands:
                        print("%s:%d: %s" % (rel, line, source))
                    continue
                if work is None:
                    work = make_sandbox(os.path.join(root, rel.replace(os.sep, "_")), repo, build, shared)
                state = os.path.join(root, "state", rel.replace(os.sep, "_"), str(k))
                t0 = time.monotonic()
                result = run_block(block, commands, work, state, args.timeout)
                ran += 1
                if result is None:
                    print("ok   %s:%d (%d commands, %.1f s)" % (rel, block.fence_line, len(commands),
                                                               time.monotonic() - t0))
                else:
                    line, message = result
                    source = dict(commands).get(line, "")
                    failures.append("%s:%d: %s\n    $ %s\n%s" % (rel, line, message.split("\n")[0],
                                                               source.replace("\n", "\n      "),
                                                               "\n".join(message.split("\n")[1:])))
                    print("FAIL %s:%d" % (rel, line))
    finally:
        if args.keep:
            print("sandbox kept: %s" % root)
        else:
            shutil.rmtree(root, ignore_errors=True)
    if args.list:
        return 0
    print("check-docs: %d block(s) run, %d no-check, %d failed" % (ran, skipped, len(failures)))
    for f in failures:
        print(f.rstrip())
    return 1 if failures else 0


if __name__ == "__main__":
    sys.stdout.reconfigure(line_buffering=True)  # progress lines in order under ctest
    sys.exit(main())
