"""The code lives in python/gearrattle/monolithic.py; this alias keeps the tests'
`import monolithic` working."""
import sys
from gearrattle import monolithic
sys.modules[__name__] = monolithic
