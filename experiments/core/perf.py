"""Hardware counters through Linux ``perf stat``, where the machine allows
them (a VM often does not): instructions and cache misses of one command.
Used by notebooks/cache.py; never needed by the experiments."""
import shutil
import subprocess

EVENTS = ("instructions", "cache-references", "cache-misses")


def stat(argv, events=EVENTS):
    """({event: count}, "") for the command ``argv``, or (None, why not)."""
    if shutil.which("perf") is None:
        return None, "perf is not installed (Debian: linux-perf)"
    try:
        proc = subprocess.run(["perf", "stat", "-x", ",", "-e", ",".join(events), "--"] + argv,
                              capture_output=True, text=True, timeout=600)
    except (OSError, subprocess.TimeoutExpired) as e:
        return None, f"perf stat failed: {e}"
    counts, missing = {}, []
    for line in proc.stderr.splitlines():
        fields = line.split(",")
        if len(fields) < 3 or fields[2] not in events:
            continue
        try:
            counts[fields[2]] = int(fields[0])
        except ValueError:  # "<not supported>" or "<not counted>"
            missing.append(f"{fields[2]}: {fields[0]}")
    if proc.returncode != 0 or missing or not counts:
        return None, ("perf stat cannot count here (" + ("; ".join(missing) or
                                                          proc.stderr.strip()[-200:]) + ")")
    return counts, ""


def available():
    """(True, "") when perf stat counts instructions and cache misses here."""
    counts, why = stat(["true"])
    return counts is not None, why
