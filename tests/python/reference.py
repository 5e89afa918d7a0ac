"""The independent reference lives in python/gearrattle/reference.py; this alias keeps the
tests' `import reference` working."""
import sys
from gearrattle import reference
sys.modules[__name__] = reference
