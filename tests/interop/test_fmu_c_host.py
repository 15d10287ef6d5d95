"""The FMU runs in an importer that is no Python process: a C program
(``c_host.c``) loads its binary, which starts the Python the FMU was
exported with (libpython, linked at export) and finds acausal through the
exporting environment's paths. Its output matches the closed form."""
import os
import pathlib
import shutil
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from acausal.interop.fmu import export_fmu

HERE = pathlib.Path(__file__).resolve().parent
OSCILLATOR = HERE.parent.parent / "models" / "examples" / "oscillator.py"


@pytest.mark.skipif(not sys.platform.startswith("linux") or not shutil.which("cc"),
                    reason="needs Linux and a C compiler")
def test_fmu_in_a_c_importer(tmp_path):
    fmu = export_fmu(OSCILLATOR, tmp_path / "osc.fmu", outputs=["mass.s"])
    with zipfile.ZipFile(fmu) as z:
        z.extractall(tmp_path / "x")
        xml = z.read("modelDescription.xml").decode()
    guid = xml.split('guid="', 1)[1].split('"', 1)[0]
    vr = xml.split('name="mass.s" valueReference="', 1)[1].split('"', 1)[0]
    host = tmp_path / "c_host"
    subprocess.run(["cc", "-O1", "-o", str(host), str(HERE / "c_host.c"), "-ldl"], check=True)
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("PYTHON", "VIRTUAL_ENV"))}
    env["PATH"] = "/usr/bin:/bin"
    proc = subprocess.run([str(host), str(tmp_path / "x" / "binaries" / "linux64" / "oscillator.so"),
                           (tmp_path / "x" / "resources").as_uri(), guid, vr, "1.0", "50"],
                          capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr
    t, s = np.loadtxt(proc.stdout.splitlines()).T
    assert len(t) == 50 and t[-1] == pytest.approx(1.0)
    assert np.max(np.abs(s - 0.1 * np.cos(10 * t))) / 0.2 < 2e-6
