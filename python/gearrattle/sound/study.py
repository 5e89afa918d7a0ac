"""The sound of a study point (--sound on map, doe and mc): the point's FMU instance stepped
finely over the statistics window instead of in one step, the default modal housing, and three
columns per point with what they cost (docs/SOUND.md, "In studies")."""

import time

COLUMNS = ("sound_N5", "sound_sharpness", "sound_LA")  # sone, acum, dB(A)
COST = "sound_cpu_s"  # CPU time of the fine stepping, the filtering and the metrics

_MD = {}  # extracted FMU directory -> fmpy model description, per process


def point(fmu, unzipdir, values, duration, t_from):
    """Advance an initialised fmpy instance from 0 to duration, recording the mesh forces from
    t_from on; the sound columns of the point. The instance ends at `duration` as after one
    step (GearRattle serves the finer communication points from its dense output)."""
    from fmpy import read_model_description

    from .meshes import SUBSAMPLE, meshes, record
    from .metrics import metrics
    from .modal import ModalTransfer
    from .render import render

    t0 = time.process_time()
    md = _MD.get(unzipdir) or _MD.setdefault(unzipdir, read_model_description(unzipdir))
    if t_from > 0:
        fmu.doStep(0.0, t_from)
    run = record(fmu, meshes(md, values), t_from, duration)
    m = metrics(render(run, ModalTransfer(), SUBSAMPLE).mix)
    return {"sound_N5": m.N5, "sound_sharpness": m.sharpness, "sound_LA": m.LAeq,
            COST: time.process_time() - t0}
