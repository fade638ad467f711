"""asv's benchmarks of lfqt (benchmarks.py).

The harness's packages (``generators``) are not installed with lfqt: they
are found in the repository that holds this folder.  It goes at the end of
sys.path, after the installed packages, so that the lfqt asv measures is the
one it installed from the commit under test, not the working tree's."""
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if ROOT not in sys.path:
    sys.path.append(ROOT)
