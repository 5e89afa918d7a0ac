"""--sound on a study: the sound columns per point and their cost in the summary, the stat_*
columns unchanged, and nothing of the sound without the flag."""

import numpy as np
import pyarrow.parquet as pq

from gearrattle.sound.study import COLUMNS, COST
from gearrattle.study.cli import main
from sound_support import fmu


def study(out, *flags):
    assert main(["map", "--fmu", fmu(), "--x", "f_exc=30:60:2", "--y", "A_rms=300:300:1",
                 "--duration", "0.3", "--workers", "0", "--quiet", "--out", str(out),
                 *flags]) == 0
    return pq.read_table(out / "points.parquet").to_pandas()


def test_sound_adds_its_columns_and_leaves_the_metrics(tmp_path):
    loud = study(tmp_path / "sound", "--sound")
    quiet = study(tmp_path / "plain")
    assert all(np.isfinite(loud[c]).all() for c in (*COLUMNS, COST))
    assert (loud["sound_N5"] > 1).all() and (loud["sound_LA"] > 30).all()
    assert not set(COLUMNS) & set(quiet.columns)
    stats = [c for c in quiet.columns if c.startswith("stat_")]
    assert stats and loud[stats].equals(quiet[stats])
    summary = (tmp_path / "sound" / "summary.txt").read_text()
    assert "sound: CPU per point" in summary and "sound_N5" in summary
