"""fuzzyvox: confidence-aware 3D mapping with dual-set fuzzy voxel maps.

The maps (:class:`FuzzyMap`, :class:`LogOddsMap`, :class:`AlphaCutMap`) integrate point clouds
and interval depth images given as numpy arrays, answer queries on arrays of points and boxes,
save and load native ``.fvx`` files, export OctoMap ``.bt`` and PLY files, and pickle through
their native bytes (so they travel between processes, for example Dask workers).
:func:`plan` runs A* through any map; :class:`Scenario`, :class:`GroundTruth` and
:func:`run_experiment` run the simulated scenarios and measure maps against their truth;
:func:`rgbd` and :func:`mono` run the held-out experiments on real data.

Voxel classes are returned as int8 codes, in the order of :data:`CLASS_NAMES`:
0 occupied, 1 free, 2 ambiguous, 3 unknown (or as names with ``classes(points, names=True)``).
"""

from ._errors import FuzzyvoxError, InvalidInputError, MapFileError, PlanError
from ._native import (
    CLASS_NAMES,
    AlphaCutMap,
    Experiment,
    FuzzyMap,
    GroundTruth,
    LogOddsMap,
    Operator,
    Plan,
    RgbdFolder,
    Scenario,
    __version__,
    bag_info,
    from_bytes,
    load,
    mono,
    operators,
    parse_operator,
    plan,
    read_bag,
    read_cloud,
    rgbd,
    run_experiment,
)

#: The three map classes, for ``isinstance`` checks.
MAP_CLASSES = (FuzzyMap, LogOddsMap, AlphaCutMap)

#: Class codes by name.
OCCUPIED, FREE, AMBIGUOUS, UNKNOWN = range(4)

__all__ = [
    "AMBIGUOUS",
    "CLASS_NAMES",
    "FREE",
    "MAP_CLASSES",
    "OCCUPIED",
    "UNKNOWN",
    "AlphaCutMap",
    "Experiment",
    "FuzzyMap",
    "FuzzyvoxError",
    "GroundTruth",
    "InvalidInputError",
    "LogOddsMap",
    "MapFileError",
    "Operator",
    "Plan",
    "PlanError",
    "RgbdFolder",
    "Scenario",
    "__version__",
    "bag_info",
    "from_bytes",
    "load",
    "mono",
    "operators",
    "parse_operator",
    "plan",
    "read_bag",
    "read_cloud",
    "rgbd",
    "run_experiment",
]
