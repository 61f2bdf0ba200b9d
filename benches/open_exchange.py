#!/usr/bin/env python3
"""What the exchange of an open L-system costs (issue 36): the whole
command, `subgram derive MODEL -o FILE`, for a model of N sensors over 100
steps, with

* no environment (the same program without its `.e` file),
* the built-in honda81,
* an external program: the crate's stand-in (`examples/stand_in_env.rs`,
  built in release), answering every module,
* vlab's own honda81 as a process (`--env-process`), where
  `$LPFG_HOME/bin/honda81` exists (../shared/tools/lpfg/build_enviro.sh),
* lpfg itself with vlab's honda81, where `$LPFG_HOME/bin/lpfg` exists
  (through ../shared/tools/lpfg/run_lpfg.sh, which adds its own start-up).

Medians of 5 runs, wall seconds; each line also gives the cost per step of
the exchange (the run less the run without an environment, over the
steps). Usage, from the clone's root, after `cargo build --release
--example stand_in_env`:

    python3 benches/open_exchange.py [N ...]
"""
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target/release/subgram")
STAND_IN = os.path.join(ROOT, "target/release/examples/stand_in_env")
LPFG_HOME = os.environ.get("LPFG_HOME", "/opt/lpfg")
STEPS = 100


def program(n):
    # n sensors on a circle of radius n (no collisions: every answer 1),
    # each after an F; the productions keep them.
    axiom = " ".join(
        f"SB() Right({360.0 * i / n:.4f}) f({n}) E1(0.5) EB()" for i in range(n)
    )
    return (
        "#include <lpfgall.h>\n"
        f"derivation length: {STEPS};\n"
        f"Axiom: {axiom};\n"
        "E1(x) : { produce E1(x); }\n"
    )


def folder(base, name, n, executable):
    d = os.path.join(base, name)
    os.makedirs(d)
    with open(os.path.join(d, "lsystem.l"), "w") as f:
        f.write(program(n))
    if executable:
        with open(os.path.join(d, "commfile.e"), "w") as f:
            f.write(
                f"executable: {executable}\ncommunication type: files\n"
                "turtle position: P: %f %f %f\n"
            )
        with open(os.path.join(d, "density.spec"), "w") as f:
            f.write("radius: 0.5\n3d case: on\n")
    return d


def timed(cmd, env=None):
    runs = []
    for _ in range(5):
        t = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
        runs.append(time.perf_counter() - t)
    return statistics.median(runs)


def main():
    sizes = [int(a) for a in sys.argv[1:]] or [1, 1000]
    base = tempfile.mkdtemp(prefix="subgram-open-bench-")
    out = os.path.join(base, "word.txt")
    try:
        for n in sizes:
            rows = []
            plain = folder(base, f"plain{n}", n, None)
            t0 = timed([BIN, "derive", plain, "-o", out])
            rows.append(("no environment", t0))
            built = folder(base, f"built{n}", n, "honda81 -e commfile.e density.spec")
            rows.append(("built-in honda81", timed([BIN, "derive", built, "-o", out])))
            if os.path.exists(STAND_IN):
                ext = folder(base, f"ext{n}", n, f"{STAND_IN} -e commfile.e sum")
                rows.append(("stand-in process", timed([BIN, "derive", ext, "-o", out])))
            vlab = os.path.join(LPFG_HOME, "bin/honda81")
            if os.path.exists(vlab):
                env = dict(os.environ, PATH=os.path.join(LPFG_HOME, "bin") + ":" + os.environ["PATH"])
                rows.append(
                    ("vlab honda81 process", timed([BIN, "derive", built, "-o", out, "--env-process"], env))
                )
            run_lpfg = os.path.join(ROOT, "../shared/tools/lpfg/run_lpfg.sh")
            if os.path.exists(os.path.join(LPFG_HOME, "bin/lpfg")) and os.path.exists(run_lpfg):
                env = dict(os.environ, LPFG_NO_IMAGE="1")
                lp = os.path.join(base, f"lpfg{n}")
                rows.append(
                    ("lpfg + vlab honda81", timed([run_lpfg, os.path.join(built, "lsystem.l"), lp], env))
                )
            print(f"{n} sensors, {STEPS} steps (median of 5, wall s; exchange per step vs no environment)")
            for name, t in rows:
                per = (t - t0) / STEPS * 1e3
                print(f"  {name:22} {t:8.3f} s   {per:8.3f} ms/step")
    finally:
        shutil.rmtree(base, ignore_errors=True)


if __name__ == "__main__":
    main()
