#!/usr/bin/env python3
"""Helpers of tools/results (standard library only).

record DIR [--stdout FILE] -- CMD...
    Runs CMD and writes DIR/run.csv (what, value): the command, the date, the wall time,
    the machine, the CPU, the Vulkan device texgeo uses, texgeo's version and commit, the
    load average before and after, the CPU time CMD and its children took, and the share
    of all cores' time other processes took meanwhile (from /proc/stat). With --stdout,
    CMD's standard output goes to DIR/FILE (written whole when CMD succeeds). Exits with
    CMD's status; run.csv is written only when CMD succeeds.

runs DOCS
    DOCS/bench/runs.csv: one row per saved report (DOCS/bench/*/run.csv and
    DOCS/report/csv/run.csv): folder, command, date, wall time, load averages, others' share.

alternate OUT.csv RUNS NAME -- CMD... -- NAME -- CMD...
    Whole processes timed in alternation (A, B, A, B, …; RUNS each, after one warm-up run of
    each), so that load from other work hits both alike: per side its median, fastest and
    slowest wall time, and the median of the per-pair ratios to the first side.

sweep-summary OUT.csv TASK=DIR...
    One row per sweep folder from its sweep.csv: meshes, ok, refused (with the reasons
    counted), failed, crashed, timeout, and the wall time the sweep's log recorded.
"""
import csv
import json
import os
import platform
import shlex
import subprocess
import sys
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def write_csv(path, rows):
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        csv.writer(f, lineterminator="\n").writerows(rows)
    os.replace(tmp, path)


def loadavg():
    with open("/proc/loadavg") as f:
        return ", ".join(f.read().split()[:3])


def cpu_jiffies():
    """(busy, total) jiffies of all cores."""
    with open("/proc/stat") as f:
        fields = [int(x) for x in f.readline().split()[1:]]
    idle = fields[3] + (fields[4] if len(fields) > 4 else 0)
    total = sum(fields[:8])
    return total - idle, total


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def memory_gib():
    with open("/proc/meminfo") as f:
        for line in f:
            if line.startswith("MemTotal:"):
                return int(line.split()[1]) / 2**20
    return 0.0


def os_name():
    try:
        with open("/etc/os-release") as f:
            for line in f:
                if line.startswith("PRETTY_NAME="):
                    return line.split("=", 1)[1].strip().strip('"')
    except OSError:
        pass
    return platform.system()


def texgeo_binary():
    return os.environ.get("TEXGEO_BIN", os.path.join(ROOT, "target", "release", "texgeo"))


def device():
    """The device texgeo opens, as `texgeo info --json` names it."""
    try:
        out = subprocess.run([texgeo_binary(), "info", "--json"], capture_output=True, check=True).stdout
        d = json.loads(out)["device"]
        return f"{d['name']} ({d['kind']}); driver {d['driver']} {d['driver_info']}; Vulkan {d['api_version']}"
    except (OSError, subprocess.CalledProcessError, ValueError, KeyError) as e:
        return f"unknown ({e})"


def version():
    try:
        v = subprocess.run([texgeo_binary(), "--version"], capture_output=True, check=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        v = "texgeo (not built)"
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short=12", "HEAD"], capture_output=True, text=True)
    return f"{v} (commit {commit.stdout.strip() or 'unknown'})"


def record(argv):
    if "--" not in argv:
        sys.exit("usage: tools/results.py record DIR [--stdout FILE] -- CMD...")
    split = argv.index("--")
    opts, cmd = argv[:split], argv[split + 1:]
    folder, stdout_name = opts[0], None
    if len(opts) == 3 and opts[1] == "--stdout":
        stdout_name = opts[2]
    elif len(opts) != 1 or not cmd:
        sys.exit("usage: tools/results.py record DIR [--stdout FILE] -- CMD...")
    os.makedirs(folder, exist_ok=True)
    dev = device()
    date = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    load_before = loadavg()
    busy0, total0 = cpu_jiffies()
    start = time.perf_counter()
    out = open(os.path.join(folder, stdout_name + ".tmp"), "wb") if stdout_name else None
    proc = subprocess.Popen(cmd, stdout=out)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    busy1, total1 = cpu_jiffies()
    load_after = loadavg()
    code = os.waitstatus_to_exitcode(status)
    if out:
        out.close()
    if code != 0:
        if out:
            os.remove(out.name)
        print(f"tools/results: {' '.join(cmd)} failed (status {code}); {folder} keeps its old run.csv",
              file=sys.stderr)
        sys.exit(code if code > 0 else 2)
    if out:
        os.replace(out.name, os.path.join(folder, stdout_name))
    hz = os.sysconf("SC_CLK_TCK")
    own = usage.ru_utime + usage.ru_stime
    cores = os.cpu_count() or 1
    others = max(0.0, (busy1 - busy0) / hz - own)
    share = 100.0 * others / max((total1 - total0) / hz, 1e-9)
    command = shlex.join(cmd).replace(ROOT + "/", "")
    rows = [
        ["what", "value"],
        ["command", command],
        ["date", date],
        ["wall time (s)", f"{wall:.1f}"],
        ["machine", f"{platform.node()} ({os_name()}, Linux {platform.release()})"],
        ["CPU", f"{cpu_model()} ({cores} cores), {memory_gib():.1f} GiB"],
        ["device", dev],
        ["texgeo", version()],
        ["load average before (1, 5, 15 min)", load_before],
        ["load average after (1, 5, 15 min)", load_after],
        ["CPU time of the run (s)", f"{own:.1f}"],
        ["other processes (% of all cores' time)", f"{share:.0f}"],
    ]
    write_csv(os.path.join(folder, "run.csv"), rows)
    print(f"tools/results: {folder}: {wall:.1f} s, load {load_before} -> {load_after}, others {share:.0f} %",
          file=sys.stderr)


def runs(argv):
    docs = argv[0]
    bench = os.path.join(docs, "bench")
    folders = [("report", os.path.join(docs, "report", "csv", "run.csv"))]
    folders += [(f"bench/{d}", os.path.join(bench, d, "run.csv")) for d in sorted(os.listdir(bench))
                if os.path.isfile(os.path.join(bench, d, "run.csv"))]
    rows = [["saved report", "command", "date", "wall (s)", "load average before", "load average after",
             "other processes (%)"]]
    for name, path in folders:
        if not os.path.isfile(path):
            continue
        with open(path, newline="") as f:
            v = {r[0]: r[1] for r in csv.reader(f) if len(r) == 2}
        if name == "report":
            # texgeo reproduce's own run.csv names the same things its own way.
            before, after = (v.get("load average (1, 5, 15 min)", "").replace("before ", "").split("; after ")
                             + ["", ""])[:2]
            rows.append([name, "target/release/texgeo reproduce --quick -o out/results/reproduce (its csv/ and run.json kept)", v.get("date", ""),
                         v.get("run time", "").removesuffix(" s"), before, after,
                         v.get("other processes", "").split(" %")[0]])
            continue
        rows.append([name, v.get("command", ""), v.get("date", ""), v.get("wall time (s)", ""),
                     v.get("load average before (1, 5, 15 min)", ""), v.get("load average after (1, 5, 15 min)", ""),
                     v.get("other processes (% of all cores' time)", "")])
    write_csv(os.path.join(bench, "runs.csv"), rows)


def alternate(argv):
    out, runs = argv[0], int(argv[1])
    rest, sides = argv[2:], []
    while rest:
        name = rest[0]
        if len(rest) < 3 or rest[1] != "--":
            sys.exit("usage: tools/results.py alternate OUT.csv RUNS NAME -- CMD... -- NAME -- CMD...")
        cmd = rest[2:]
        end = next((i for i in range(len(cmd) - 1) if cmd[i] == "--" and cmd[i + 2:i + 3] == ["--"]), len(cmd))
        sides.append((name, cmd[:end]))
        rest = cmd[end + 1:]
    times = {name: [] for name, _ in sides}
    for k in range(runs + 1):
        for name, cmd in sides:
            t = time.perf_counter()
            p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
            if p.returncode != 0:
                sys.exit(f"{' '.join(cmd)} failed (status {p.returncode}):\n{p.stderr.decode()}")
            if k > 0:  # the first round warms caches up
                times[name].append(time.perf_counter() - t)
    median = lambda v: sorted(v)[len(v) // 2] if len(v) % 2 else sum(sorted(v)[len(v) // 2 - 1:len(v) // 2 + 1]) / 2
    first = times[sides[0][0]]
    rows = [["side", "command", "runs", "median s", "fastest s", "slowest s", f"ratio to {sides[0][0]} (median of pairs)"]]
    for name, cmd in sides:
        v = times[name]
        ratio = median([a / b for a, b in zip(v, first)])
        rows.append([name, shlex.join(cmd).replace(ROOT + "/", ""), str(len(v)), f"{median(v):.3f}", f"{min(v):.3f}",
                     f"{max(v):.3f}", f"{ratio:.2f}"])
    os.makedirs(os.path.dirname(out) or ".", exist_ok=True)
    write_csv(out, rows)


def sweep_summary(argv):
    out, pairs = argv[0], argv[1:]
    rows = [["task", "meshes", "ok", "refused", "refused, by reason", "failed", "crashed", "timeout"]]
    for pair in pairs:
        task, folder = pair.split("=", 1)
        with open(os.path.join(folder, "sweep.csv"), newline="") as f:
            records = list(csv.DictReader(f))
        count = lambda o: sum(r["outcome"] == o for r in records)
        reasons = {}
        for r in records:
            if r["outcome"] == "refused":
                reasons[r["reason"]] = reasons.get(r["reason"], 0) + 1
        why = "; ".join(f"{k} {n}" for k, n in sorted(reasons.items(), key=lambda kv: (-kv[1], kv[0])))
        rows.append([task, str(len(records)), str(count("ok")), str(count("refused")), why,
                     str(count("failed")), str(count("crashed")), str(count("timeout"))])
    write_csv(out, rows)


if __name__ == "__main__":
    commands = {"record": record, "runs": runs, "alternate": alternate, "sweep-summary": sweep_summary}
    if len(sys.argv) < 2 or sys.argv[1] not in commands:
        sys.exit(f"usage: tools/results.py {'|'.join(commands)} ...")
    commands[sys.argv[1]](sys.argv[2:])
