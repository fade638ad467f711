"""What a result records about the machine it was measured on: CPU model,
caches, cores, memory, transparent huge pages, free page reporting (a VM
giving freed memory back to its host), library versions and the commit."""
import hashlib
import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path

from lfqt import pages


def machine_info():
    """CPU model, caches, cores, library versions, commit."""
    info = {"python": platform.python_version(), "platform": platform.platform(),
            "cores": os.cpu_count()}
    info.update(cpu_details())
    info.update(topology())
    info["caches"] = cache_sizes()
    info["transparent_hugepages"] = transparent_hugepages()
    info["free_page_reporting_order"] = free_page_reporting_order()
    # whether a balloon actually reports (the order exists wherever the kernel could);
    # lfqt's 3D insertion then keeps off huge pages (lfqt.pages)
    info["host_takes_free_pages"] = pages.host_takes_free_pages()
    try:
        info["memory_bytes"] = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError):
        pass
    versions = {}
    for pkg in ("numpy", "numba", "scipy", "pandas", "triangle", "lfqt"):
        try:
            versions[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:  # not installed: not listed
            pass
    info["versions"] = versions
    info["code"] = code_version()
    if info["code"]:
        info["commit"] = info["code"].split("+")[0]
    return info


# what a measurement depends on, for code_version's uncommitted changes
CODE_PATHS = ("lfqt", "drivers", "generators", "experiments", "setup.sh", "pyproject.toml")


def code_version():
    """The commit, with a hash of the uncommitted changes to the measured
    code (CODE_PATHS) when there are any: the runner measures again a cell
    measured on other code.  None outside a git checkout."""
    root = Path(__file__).resolve().parents[2]
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                              cwd=root)
        diff = subprocess.run(["git", "diff", "HEAD", "--", *CODE_PATHS], capture_output=True,
                              cwd=root)
    except OSError:
        return None
    if head.returncode != 0 or diff.returncode != 0:
        return None
    commit = head.stdout.strip()
    if diff.stdout:
        return f"{commit}+{hashlib.sha1(diff.stdout).hexdigest()[:12]}"
    return commit


def cpu_details():
    """The CPU as /proc/cpuinfo names it: model name, vendor, family, model,
    stepping, and the vector extensions that matter for -march=native."""
    fields = {}
    try:
        for line in open("/proc/cpuinfo"):
            if ":" in line:
                k, v = (x.strip() for x in line.split(":", 1))
                fields.setdefault(k, v)
            elif fields:
                break  # the first processor is enough
    except OSError:
        return {"cpu": platform.processor()}
    flags = set(fields.get("flags", "").split())
    return {"cpu": fields.get("model name", platform.processor()),
            "cpu_vendor": fields.get("vendor_id", ""),
            "cpu_family_model_stepping": "/".join(fields.get(k, "?") for k in
                                                  ("cpu family", "model", "stepping")),
            "cpu_isa": sorted(flags & {"sse4_2", "avx", "avx2", "fma", "bmi2", "avx512f",
                                       "avx512vl", "amx_tile"})}


def topology():
    """{"logical_cpus", "physical_cores", "sockets"} from sysfs: a logical
    CPU beyond the physical cores is an SMT sibling (paper 1, Fig. 6 marks
    that boundary)."""
    cores, sockets, logical = set(), set(), 0
    for cpu in Path("/sys/devices/system/cpu").glob("cpu[0-9]*"):
        try:
            core = (cpu / "topology" / "core_id").read_text().strip()
            package = (cpu / "topology" / "physical_package_id").read_text().strip()
        except OSError:
            continue
        logical += 1
        cores.add((package, core))
        sockets.add(package)
    if not logical:
        return {"logical_cpus": os.cpu_count(), "physical_cores": os.cpu_count()}
    return {"logical_cpus": logical, "physical_cores": len(cores), "sockets": len(sockets)}


def transparent_hugepages(base=Path("/sys/kernel/mm/transparent_hugepage")):
    """{"enabled": mode, "defrag": mode} as the kernel selects them ("always",
    "madvise", "never", ...), {} where there are none.  Fresh memory costs
    differ by the mode: from one session to the next, "always" against
    "madvise" moved first calls at 1M points by up to 0.6 s."""
    out = {}
    for name in ("enabled", "defrag"):
        try:
            text = (base / name).read_text()
        except OSError:
            continue
        chosen = [w[1:-1] for w in text.split() if w.startswith("[") and w.endswith("]")]
        if chosen:
            out[name] = chosen[0]
    return out


def free_page_reporting_order(base=Path("/sys/module/page_reporting/parameters")):
    """The order (log2 of 4 KiB pages) of the free blocks a guest hands back
    to its host (virtio free page reporting), or None where the kernel does
    not report.  On such a VM a freed block the host took back faults on
    the host when touched again: a fresh 2 MiB huge page cost 1.7-3.3 ms on
    our Firecracker VMs (order 9), and the 208 MB of a 3D output at 1M
    points 35 ms to 430 ms of system time from one call to the next."""
    try:
        return int((base / "page_reporting_order").read_text())
    except (OSError, ValueError):
        return None


def cache_sizes():
    """{"L1d": bytes, "L2": bytes, "L3": bytes} from sysfs (cpu0)."""
    out = {}
    base = Path("/sys/devices/system/cpu/cpu0/cache")
    for idx in sorted(base.glob("index*")):
        try:
            level = (idx / "level").read_text().strip()
            kind = (idx / "type").read_text().strip()
            size = (idx / "size").read_text().strip()
        except OSError:
            continue
        mult = {"K": 1024, "M": 1024 ** 2}.get(size[-1], 1)
        name = f"L{level}" + ("d" if kind == "Data" else "i" if kind == "Instruction" else "")
        out[name] = int(size.rstrip("KM")) * mult
    return out


def available_memory():
    try:
        for line in open("/proc/meminfo"):
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None
