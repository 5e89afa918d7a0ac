"""The machine a measurement ran on, read the same way by every report that prints it."""

import subprocess


def lscpu() -> dict:
    """lscpu's fields (Model name, CPU(s), Hypervisor vendor...); empty without lscpu."""
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return {}
    d = {}
    for line in out.splitlines():
        if ":" in line:
            k, v = line.split(":", 1)
            d[k.strip()] = v.strip()
    return d
