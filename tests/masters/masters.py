"""The code lives in python/gearrattle/masters.py; this alias keeps the tests'
`import masters` working."""
import sys
from gearrattle import masters
sys.modules[__name__] = masters
