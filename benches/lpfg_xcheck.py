#!/usr/bin/env python3
"""Cross-check subgram's final words against lpfg's. Not part of `cargo test`
or `.ci/run`; Python 3 standard library only.

    python3 benches/lpfg_xcheck.py [OPTIONS] PROGRAM...

A PROGRAM is an L+C file (`.l`), a subgram file (`.lsys`, copied for lpfg as
`NAME.l` with `#include <lpfgall.h>` put in front when it lacks one), or a
vlab model folder (its `.l` file is the one MAIN names, else the one the
`lpfg` line of `specifications` names, else `lsystem.l`, else the folder's
only `.l` file).

The real-model corpus: `--models benches/lpfg_models.txt --vlab GIT_DIR
--extract-to DIR` copies each listed model folder of the vlab repository
(github.com/AlgorithmicBotany/vlab, GPL-3.0; the files stay outside this
project because of the licence) from the git directory into DIR/NAME (its
own files only, not its `ext/` sub-objects) and checks them with the other
PROGRAMs. `--models` without `--vlab` takes the folders already in DIR.

For each program it runs
  * lpfg, through `run_lpfg.sh PROGRAM.l OUTDIR` (see
    ../shared/tools/lpfg/README.md; `--lpfg-run`, default $LPFG_RUN or
    /work/shared/tools/lpfg/run_lpfg.sh), without a picture unless
    `--image`. Its outputs are cached under `--cache` (default
    /tmp/lpfg-cache) in a folder named by the SHA-256 of the program's
    folder (every plain file in it) and the `.l` file's name; `--refresh`
    runs lpfg again. Timeouts are not cached.
  * subgram: `subgram derive --format json PROGRAM` (`--subgram`, default
    target/release/subgram). A model folder is given as the folder, or as
    its `.l` file with `--subgram-input file` (for a subgram that does not
    read folders yet).
and compares the final words: the same module names in the same order, and
each numeric parameter equal to `--rel` (1e-5) relative, or `--abs` (1e-9)
absolute near zero. Vectors (`V2f(x,y)`) compare component by component.
lpfg prints a struct parameter as its raw bytes `<hex:...>`; they are decoded
with the field types of subgram's JSON (integers as int32, floats as float32,
or float64 when only that fits the byte count, bools as one byte, C
alignment).

Output: a table (program, lpfg's module count, subgram's, verdict) and the
line "N of M programs give the same modules with parameters to 1e-5
relative". Verdicts: `same`; `differs at module k` with both modules
(1-based), and whether the names alone agree; `subgram error` (its first
line); `lpfg error` (the first error line of lpfg's log); `timeout`.
`--json` prints one JSON object instead: {"programs": [...], "summary": ...}.

Examples:
    python3 benches/lpfg_xcheck.py /work/shared/corpus/lpfg/*.l
    python3 benches/lpfg_xcheck.py --models benches/lpfg_models.txt \\
        --vlab /work/.mirror/AlgorithmicBotany+vlab/repo \\
        --extract-to /work/realmodels --subgram-input file
"""
import argparse
import hashlib
import json
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)

# --------------------------------------------------------------------------
# finding the program of a folder


def main_l_file(folder):
    """The `.l` file lpfg runs for a model folder, or None."""
    main = os.path.join(folder, "MAIN")
    if os.path.isfile(main):
        with open(main, encoding="latin-1") as f:
            name = f.readline().strip()
        if name:
            return name
    spec = os.path.join(folder, "specifications")
    if os.path.isfile(spec):
        with open(spec, encoding="latin-1") as f:
            for line in f:
                toks = line.split()
                if any(t == "lpfg" or t.endswith("/lpfg") for t in toks):
                    for t in toks:
                        if t.endswith(".l") and os.path.isfile(os.path.join(folder, t)):
                            return t
    if os.path.isfile(os.path.join(folder, "lsystem.l")):
        return "lsystem.l"
    ls = sorted(f for f in os.listdir(folder) if f.endswith(".l"))
    return ls[0] if len(ls) == 1 else None


class Program:
    """One program to check: what lpfg runs and what subgram runs."""

    def __init__(self, path, subgram_input, tmp):
        self.path = os.path.abspath(path)
        self.label = path
        self.error = None
        self.lpfg_file = None  # the .l file run_lpfg.sh runs
        self.subgram_arg = self.path
        if os.path.isdir(self.path):
            name = main_l_file(self.path)
            if name is None:
                self.error = "no .l file found in the folder (no MAIN, specifications or lsystem.l)"
                return
            self.lpfg_file = os.path.join(self.path, name)
            if subgram_input == "file":
                self.subgram_arg = self.lpfg_file
        elif self.path.endswith(".lsys"):
            # lpfg wants NAME.l and its header; copy the file alone into a folder
            base = os.path.splitext(os.path.basename(self.path))[0]
            d = os.path.join(tmp, "lsys-" + hashlib.sha256(self.path.encode()).hexdigest()[:12])
            os.makedirs(d, exist_ok=True)
            with open(self.path, encoding="utf-8") as f:
                text = f.read()
            if "lpfgall.h" not in text:
                text = "#include <lpfgall.h>\n#line 1\n" + text
            self.lpfg_file = os.path.join(d, base + ".l")
            with open(self.lpfg_file, "w", encoding="utf-8") as f:
                f.write(text)
        else:
            self.lpfg_file = self.path

    def cache_key(self):
        h = hashlib.sha256()
        folder = os.path.dirname(self.lpfg_file)
        h.update(os.path.basename(self.lpfg_file).encode() + b"\0")
        h.update(os.environ.get("LPFG_ARGS", "").encode() + b"\0")
        for name in sorted(os.listdir(folder)):
            p = os.path.join(folder, name)
            if os.path.isfile(p):
                h.update(name.encode() + b"\0")
                with open(p, "rb") as f:
                    h.update(hashlib.sha256(f.read()).digest())
        return h.hexdigest()[:32]


# --------------------------------------------------------------------------
# the real-model corpus


def read_model_list(path):
    """[(vlab path, name)] from the list: one path a line, an optional name
    after it, `#` starts a comment."""
    out = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            toks = line.split()
            vpath = toks[0].rstrip("/")
            name = toks[1] if len(toks) > 1 else os.path.basename(vpath)
            out.append((vpath, name))
    return out


def extract_model(git_dir, rev, vpath, dest):
    """Copy the plain files of one vlab folder (not its sub-folders) to dest."""
    ls = subprocess.run(
        ["git", "-C", git_dir, "ls-tree", "-z", rev + ":" + vpath],
        capture_output=True, check=True).stdout.decode("utf-8", "replace")
    if os.path.isdir(dest):
        shutil.rmtree(dest)
    os.makedirs(dest)
    for entry in ls.split("\0"):
        if not entry:
            continue
        meta, name = entry.split("\t", 1)
        mode, kind, sha = meta.split()
        if kind != "blob" or mode == "120000":
            continue
        data = subprocess.run(["git", "-C", git_dir, "cat-file", "blob", sha],
                              capture_output=True, check=True).stdout
        with open(os.path.join(dest, name), "wb") as f:
            f.write(data)


# --------------------------------------------------------------------------
# running lpfg (cached) and subgram


def first_error_line(text):
    lines = [l.strip() for l in text.splitlines() if l.strip()]
    for l in lines:
        if re.search(r"\berror\b|Error|rror:|Segmentation|Aborted|core dumped|cannot|not found", l):
            return l
    return lines[-1] if lines else "(no output)"


def run_lpfg(prog, opts):
    """{'status': 'ok'|'error'|'timeout', 'string': text, 'error': line, ...}"""
    key = prog.cache_key()
    cdir = os.path.join(opts.cache, key)
    meta_path = os.path.join(cdir, "meta.json")
    if not opts.refresh and os.path.isfile(meta_path):
        with open(meta_path) as f:
            meta = json.load(f)
        meta["cached"] = True
        meta["dir"] = cdir
        if meta["status"] == "ok":
            with open(os.path.join(cdir, "string.txt"), encoding="latin-1") as f:
                meta["string"] = f.read()
        return meta
    os.makedirs(opts.cache, exist_ok=True)
    out = tempfile.mkdtemp(prefix="run-", dir=opts.cache)
    env = dict(os.environ)
    env["LPFG_TIMEOUT"] = str(opts.timeout)
    if not opts.image:
        env["LPFG_NO_IMAGE"] = "1"
    t0 = time.time()
    try:
        r = subprocess.run(["bash", opts.lpfg_run, prog.lpfg_file, out], env=env,
                           capture_output=True, timeout=3 * opts.timeout + 60)
        rc, stderr = r.returncode, r.stderr.decode("utf-8", "replace")
    except subprocess.TimeoutExpired:
        rc, stderr = 124, "run_lpfg.sh timed out"
    if rc == 2:  # run_lpfg.sh's usage errors: lpfg not installed, no such file
        shutil.rmtree(out, ignore_errors=True)
        sys.exit("run_lpfg.sh: " + stderr.strip())
    seconds = time.time() - t0
    log = ""
    lp = os.path.join(out, "lpfg_batch.log")
    if os.path.isfile(lp):
        with open(lp, encoding="utf-8", errors="replace") as f:
            log = f.read()
    meta = {"rc": rc, "seconds": round(seconds, 2), "program": prog.lpfg_file}
    names_check = os.path.join(out, "names_check.txt")
    if os.path.isfile(names_check):
        with open(names_check) as f:
            meta["names_check"] = f.read().strip()
    sp = os.path.join(out, "string.txt")
    if (rc == 0 or (not opts.image and os.path.isfile(sp) and rc == 1 and "decod" not in stderr)) \
            and os.path.isfile(sp):
        meta["status"] = "ok"
    elif rc == 124 or "rc=124" in stderr or "rc=137" in stderr:
        meta["status"] = "timeout"
        meta["error"] = "lpfg ran past %d s" % opts.timeout
    else:
        meta["status"] = "error"
        meta["error"] = first_error_line(log) if log.strip() else first_error_line(stderr)
    if meta["status"] == "timeout":
        shutil.rmtree(out, ignore_errors=True)
        meta["dir"] = None
        return meta
    with open(os.path.join(out, "meta.json"), "w") as f:
        json.dump(meta, f, indent=1)
    if os.path.isdir(cdir):
        shutil.rmtree(cdir)
    os.rename(out, cdir)
    meta["dir"] = cdir
    meta["cached"] = False
    if meta["status"] == "ok":
        with open(os.path.join(cdir, "string.txt"), encoding="latin-1") as f:
            meta["string"] = f.read()
    return meta


def run_subgram(prog, opts):
    cmd = [opts.subgram, "derive", "--format", "json", "--timeout", str(opts.timeout),
           prog.subgram_arg]
    t0 = time.time()
    try:
        r = subprocess.run(cmd, capture_output=True, timeout=opts.timeout + 30)
    except subprocess.TimeoutExpired:
        return {"status": "timeout", "error": "subgram ran past %d s" % opts.timeout}
    res = {"rc": r.returncode, "seconds": round(time.time() - t0, 2)}
    err = r.stderr.decode("utf-8", "replace")
    if r.returncode != 0:
        res["status"] = "timeout" if "past its time limit" in err else "error"
        lines = [l for l in err.splitlines() if l.strip()]
        res["error"] = lines[0] if lines else "exit code %d, nothing on stderr" % r.returncode
        res["stderr"] = err[:4000]
        return res
    try:
        res["word"] = json.loads(r.stdout)
    except ValueError as e:
        res["status"] = "error"
        res["error"] = "its JSON does not parse: %s" % e
        return res
    res["status"] = "ok"
    if err.strip():
        res["warnings"] = [l for l in err.splitlines() if l.strip()][:20]
    return res


# --------------------------------------------------------------------------
# lpfg's string: Name(p, ...) separated by spaces


class Hex:
    def __init__(self, data):
        self.data = data

    def __repr__(self):
        return "<hex:%s>" % self.data.hex()


class Raw:
    def __init__(self, text):
        self.text = text

    def __repr__(self):
        return self.text


NUM_RE = re.compile(r"[-+]?(?:nan|inf|(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)$")


def parse_lpfg_string(text):
    """[(name, [param, ...])]; a param is a number, a bool, a list (vector,
    array), a Hex or a Raw."""
    mods = []
    i, n = 0, len(text)
    while i < n:
        while i < n and text[i].isspace():
            i += 1
        if i >= n:
            break
        j = i
        while j < n and not text[j].isspace() and text[j] != "(":
            j += 1
        name = text[i:j]
        params = []
        if j < n and text[j] == "(":
            params, j = parse_args(text, j + 1, ")")
        mods.append((name, params))
        i = j
    return mods


def parse_args(text, i, close):
    out = []
    n = len(text)
    if i < n and text[i] == close:
        return out, i + 1
    while i < n:
        v, i = parse_value(text, i)
        out.append(v)
        if i < n and text[i] == ",":
            i += 1
            continue
        if i < n and text[i] == close:
            return out, i + 1
        raise ValueError("unexpected %r at %d" % (text[i:i + 10], i))
    raise ValueError("unterminated parameter list")


def parse_value(text, i):
    n = len(text)
    if text.startswith("<hex:", i):
        j = text.index(">", i)
        return Hex(bytes.fromhex(text[i + 5:j])), j + 1
    if text[i] == "{":
        vals, j = parse_args(text, i + 1, "}")
        return vals, j
    m = re.match(r"(V[23][fd])\(", text[i:])
    if m:
        vals, j = parse_args(text, i + len(m.group(0)), ")")
        return vals, j
    j = i
    depth = 0
    while j < n and (depth > 0 or text[j] not in ",)}"):
        if text[j] in "({":
            depth += 1
        elif text[j] in ")}":
            depth -= 1
        j += 1
    tok = text[i:j].strip()
    if tok == "true":
        return True, j
    if tok == "false":
        return False, j
    if NUM_RE.match(tok):
        return (float(tok) if re.search(r"[.eEna]", tok) else int(tok)), j
    return Raw(tok), j


# --------------------------------------------------------------------------
# comparison


def leaves(v):
    if isinstance(v, list):
        out = []
        for x in v:
            out.extend(leaves(x))
        return out
    return [v]


def decode_hex(data, fields, rel=1e-5, abs_=1e-9):
    """Decode raw struct bytes with subgram's field values as the types, or
    None when no layout fits the byte count. subgram's JSON does not say
    whether a float field is a float or a double: every choice whose C
    layout has the byte count is tried, and the one that agrees best with
    subgram's values is taken."""
    floats = [i for i, f in enumerate(fields)
              if not isinstance(f, (bool, int)) and (isinstance(f, float) or f is None)]
    if any(not isinstance(f, (bool, int, float)) and f is not None for f in fields):
        return None
    if len(floats) > 12:
        choices = [0, (1 << len(floats)) - 1]  # all float, all double
    else:
        choices = range(1 << len(floats))
    best, best_bad = None, None
    for mask in choices:
        doubles = {floats[k] for k in range(len(floats)) if mask >> k & 1}
        off, vals, align_max = 0, [], 1
        for i, f in enumerate(fields):
            if isinstance(f, bool):
                size, fmt = 1, "<?"
            elif isinstance(f, int):
                size, fmt = 4, "<i"
            elif i in doubles:
                size, fmt = 8, "<d"
            else:
                size, fmt = 4, "<f"
            off = (off + size - 1) // size * size
            align_max = max(align_max, size)
            if off + size > len(data):
                break
            vals.append(struct.unpack_from(fmt, data, off)[0])
            off += size
        else:
            if (off + align_max - 1) // align_max * align_max != len(data):
                continue
            bad = sum(1 for a, b in zip(vals, fields) if not close(a, b, rel, abs_))
            if best is None or bad < best_bad:
                best, best_bad = vals, bad
    return best


def close(a, b, rel, abs_):
    if isinstance(a, bool) or isinstance(b, bool):
        return bool(a) == bool(b) and isinstance(a, bool) == isinstance(b, bool)
    if b is None:  # serde_json writes NaN and infinities as null
        return isinstance(a, (int, float)) and not math.isfinite(a)
    if not isinstance(a, (int, float)) or not isinstance(b, (int, float)):
        return False
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    if a == b:
        return True
    d = abs(a - b)
    return d <= abs_ or d <= rel * max(abs(a), abs(b))


def param_same(lp, sg, rel, abs_):
    """(same, relative difference) of one parameter."""
    sl = leaves(sg)
    if isinstance(lp, Hex):
        vals = decode_hex(lp.data, sl, rel, abs_)
        if vals is None:
            return False, "struct"
        ll = vals
    else:
        ll = leaves(lp)
    if len(ll) != len(sl):
        return False, None
    worst = 0.0
    for a, b in zip(ll, sl):
        if isinstance(a, Raw) or isinstance(b, str):
            if str(a) != str(b):
                return False, None
            continue
        if not close(a, b, rel, abs_):
            return False, rel_diff(a, b)
        worst = max(worst, rel_diff(a, b) or 0.0)
    return True, worst


def rel_diff(a, b):
    try:
        a, b = float(a), float(b)
    except (TypeError, ValueError):
        return None
    if a == b or (math.isnan(a) and math.isnan(b)):
        return 0.0
    m = max(abs(a), abs(b))
    return abs(a - b) / m if m else None


def fmt_lpfg(mod):
    name, params = mod
    return "%s(%s)" % (name, ", ".join(fmt_val(p) for p in params)) if params else name


def fmt_val(v):
    if isinstance(v, list):
        return "[" + ", ".join(fmt_val(x) for x in v) + "]"
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    return str(v)


def fmt_sub(mod):
    ps = mod.get("params", [])
    name = mod.get("symbol", "?")
    return "%s(%s)" % (name, ", ".join(fmt_val(p) for p in ps)) if ps else name


def compare(lmods, smods, rel, abs_):
    """{'same': bool, 'names_same': bool, 'first': k (0-based) or None,
    'max_rel': worst relative difference among matching parameters}"""
    names_same = len(lmods) == len(smods) and all(
        l[0] == s.get("symbol") for l, s in zip(lmods, smods))
    first, why, worst = None, None, 0.0
    for k in range(max(len(lmods), len(smods))):
        if k >= len(lmods) or k >= len(smods):
            first, why = k, "one word ends"
            break
        (ln, lp), s = lmods[k], smods[k]
        sp = s.get("params", [])
        if ln != s.get("symbol"):
            first, why = k, "module name"
            break
        if len(lp) != len(sp):
            first, why = k, "parameter count"
            break
        bad = False
        for a, b in zip(lp, sp):
            ok, d = param_same(a, b, rel, abs_)
            if not ok:
                bad = True
                if d == "struct":
                    why = "struct bytes fit no layout of subgram's fields"
                else:
                    why = "parameter" + ("" if d is None else " (relative difference %.3g)" % d)
                break
            worst = max(worst, d or 0.0)
        if bad:
            first = k
            break
    return {"same": first is None, "names_same": names_same, "first": first,
            "why": why, "max_rel": worst}


# --------------------------------------------------------------------------


def check(prog, opts):
    rec = {"program": prog.label}
    if prog.error:
        rec.update(verdict="skipped", detail=prog.error)
        return rec
    rec["lpfg_file"] = prog.lpfg_file
    sg = run_subgram(prog, opts)
    if opts.no_lpfg:
        rec["subgram"] = {k: v for k, v in sg.items() if k not in ("word",)}
        rec["subgram_modules"] = len(sg["word"].get("modules", [])) if "word" in sg else "-"
        rec.update(verdict="subgram " + sg["status"], detail=sg.get("error", ""))
        return rec
    lp = run_lpfg(prog, opts)
    rec["lpfg"] = {k: v for k, v in lp.items() if k != "string"}
    rec["subgram"] = {k: v for k, v in sg.items() if k not in ("word", "stderr")}
    if sg["status"] != "ok" and "stderr" in sg:
        rec["subgram"]["stderr"] = sg["stderr"]
    lmods = smods = None
    if lp["status"] == "ok":
        try:
            lmods = parse_lpfg_string(lp["string"])
            rec["lpfg_modules"] = len(lmods)
        except ValueError as e:
            lp["status"], lp["error"] = "error", "cannot read lpfg's string.txt: %s" % e
            rec["lpfg"].update(status="error", error=lp["error"])
    if sg["status"] == "ok":
        smods = sg["word"].get("modules", [])
        rec["subgram_modules"] = len(smods)
    if lp["status"] != "ok" and sg["status"] != "ok":
        rec.update(verdict="both error",
                   detail="lpfg: %s | subgram: %s" % (lp.get("error"), sg.get("error")))
    elif lp["status"] == "timeout":
        rec.update(verdict="lpfg timeout", detail=lp["error"])
    elif lp["status"] != "ok":
        rec.update(verdict="lpfg error", detail=lp.get("error"))
    elif sg["status"] == "timeout":
        rec.update(verdict="subgram timeout", detail=sg["error"])
    elif sg["status"] != "ok":
        rec.update(verdict="subgram error", detail=sg["error"])
    else:
        c = compare(lmods, smods, opts.rel, opts.abs)
        rec["names_same"] = c["names_same"]
        rec["max_rel"] = c["max_rel"]
        if c["same"]:
            rec.update(verdict="same", detail="")
        else:
            k = c["first"]
            rec["first_diff"] = {
                "index": k + 1,
                "why": c["why"],
                "lpfg": fmt_lpfg(lmods[k]) if k < len(lmods) else None,
                "subgram": fmt_sub(smods[k]) if k < len(smods) else None,
            }
            rec.update(verdict="differs",
                       detail="at module %d (%s%s): lpfg %s, subgram %s" % (
                           k + 1, c["why"], "; names all agree" if c["names_same"] else "",
                           rec["first_diff"]["lpfg"] or "(end)",
                           rec["first_diff"]["subgram"] or "(end)"))
    if "names_check" in lp and "NONDETERMINISTIC" in lp["names_check"]:
        rec["detail"] = (rec.get("detail") or "") + " [lpfg is not deterministic between runs]"
    return rec


def clip(s, n):
    s = s or ""
    return s if len(s) <= n else s[:n - 1] + "…"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("programs", nargs="*", help=".l or .lsys files, or model folders")
    ap.add_argument("--subgram", default=os.path.join(REPO, "target", "release", "subgram"))
    ap.add_argument("--subgram-input", choices=["folder", "file"], default="folder",
                    help="give subgram a model folder as the folder (default) or its .l file")
    ap.add_argument("--lpfg-run", default=os.environ.get(
        "LPFG_RUN", "/work/shared/tools/lpfg/run_lpfg.sh"))
    ap.add_argument("--cache", default="/tmp/lpfg-cache")
    ap.add_argument("--refresh", action="store_true", help="run lpfg again, ignoring the cache")
    ap.add_argument("--image", action="store_true", help="let lpfg draw its picture too")
    ap.add_argument("--timeout", type=int, default=60, help="seconds per run (default 60)")
    ap.add_argument("--rel", type=float, default=1e-5)
    ap.add_argument("--abs", type=float, default=1e-9)
    ap.add_argument("--models", help="list of vlab model folders (benches/lpfg_models.txt)")
    ap.add_argument("--vlab", help="vlab git directory to extract the listed models from")
    ap.add_argument("--vlab-rev", default="HEAD")
    ap.add_argument("--extract-to", default="/tmp/lpfg-realmodels",
                    help="folder of the extracted models (outside the repository)")
    ap.add_argument("--json", action="store_true", help="print JSON instead of the table")
    ap.add_argument("--no-lpfg", action="store_true",
                    help="run subgram only: its errors, without a comparison")
    ap.add_argument("--width", type=int, default=110, help="width of the table's detail column")
    opts = ap.parse_args()

    paths = list(opts.programs)
    if opts.models:
        for vpath, name in read_model_list(opts.models):
            dest = os.path.join(opts.extract_to, name)
            if opts.vlab:
                extract_model(opts.vlab, opts.vlab_rev, vpath, dest)
            paths.append(dest)
    if not paths:
        ap.error("no programs: give files or folders, or --models")
    if not os.access(opts.subgram, os.X_OK):
        ap.error("no subgram binary at %s (cargo build --release, or --subgram)" % opts.subgram)
    if not opts.no_lpfg and not os.path.isfile(opts.lpfg_run):
        ap.error("no run_lpfg.sh at %s (--lpfg-run)" % opts.lpfg_run)

    tmp = tempfile.mkdtemp(prefix="lpfg-xcheck-")
    recs = []
    if not opts.json:
        print("%-50s %8s %8s  %s" % ("program", "lpfg", "subgram", "verdict"))
    try:
        for p in paths:
            prog = Program(p, opts.subgram_input, tmp)
            rec = check(prog, opts)
            recs.append(rec)
            if not opts.json:
                print("%-50s %8s %8s  %s: %s" % (
                    clip(rec["program"], 50), rec.get("lpfg_modules", "-"),
                    rec.get("subgram_modules", "-"), rec["verdict"],
                    clip(rec.get("detail"), opts.width)), flush=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    same = sum(1 for r in recs if r["verdict"] == "same")
    counts = {}
    for r in recs:
        counts[r["verdict"]] = counts.get(r["verdict"], 0) + 1
    line = "%d of %d programs give the same modules with parameters to %g relative" % (
        same, len(recs), opts.rel)
    names_only = sum(1 for r in recs if r["verdict"] == "differs" and r.get("names_same"))
    if opts.json:
        json.dump({"programs": recs, "summary": {"same": same, "programs": len(recs),
                                                 "verdicts": counts, "line": line,
                                                 "names_same_params_differ": names_only}},
                  sys.stdout, indent=1)
        print()
    else:
        print()
        print(line)
        print("verdicts: " + ", ".join("%s %d" % kv for kv in sorted(counts.items())))
        if names_only:
            print("of the 'differs': %d have the same module names, only parameters differ"
                  % names_only)


if __name__ == "__main__":
    main()
