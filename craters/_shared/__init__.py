"""Plumbing shared by the three packages, kept out of crater science (like scikit-image's
``_shared``): argument checks and random generators, files (atomic writes, output checks,
TOML), progress bars, machine facts, ``key=value`` specs, slope statistics, reports and
mesh writers. ``craters`` is the ground floor of the import graph
(``latlong -> craters <- dem``), so it lives here, privately.

The command-line helpers are in :mod:`craters.cli.kit`; nothing here imports them, so
importing a library never loads argparse.
"""

from typing import TYPE_CHECKING

from .lazy import lazy_package

if TYPE_CHECKING:  # at run time each name is imported on first use (lazy_package)
    from .files import (
        atomic_path,
        check_output_path,
        check_parent_folder,
        check_suffix,
        load_toml,
    )
    from .outputs import (
        check_outside_folder,
        output_group,
        replace_output,
        same_file,
        staged_path,
        sweep_temporaries,
        temp_file,
        temp_folder,
    )
    from .progress import progress_bar
    from .spec import parse_spec
    from .system import human_bytes, package_version, physical_memory_bytes
    from .validation import (
        ParameterError,
        ParameterTypeError,
        about,
        check_choice,
        check_finite,
        check_int,
        check_positive,
        check_range,
        normalize_rng,
        parameter_of,
    )

__all__ = ["ParameterError", "ParameterTypeError", "about",
           "atomic_path", "check_choice", "check_finite", "check_int", "check_output_path",
           "check_outside_folder",
           "check_parent_folder", "check_positive", "check_range", "check_suffix", "human_bytes",
           "load_toml", "normalize_rng", "package_version", "parameter_of",
           "parse_spec",
           "output_group", "physical_memory_bytes",
           "progress_bar", "replace_output", "same_file", "staged_path", "sweep_temporaries",
           "temp_file", "temp_folder"]

lazy_package(__name__)
