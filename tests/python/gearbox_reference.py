"""The gearbox reference lives in python/gearrattle/gearbox_reference.py (shared with
scripts/); this alias lets the tests `import gearbox_reference`."""
import sys
from gearrattle import gearbox_reference
sys.modules[__name__] = gearbox_reference
