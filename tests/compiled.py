"""What the tests of the compiled parts share."""

import shutil
import sysconfig

import pytest


def skip_without_a_compiler() -> None:
    """Skip the test on a machine without the C compiler pip would build with."""
    compiler = (sysconfig.get_config_var("CC") or "cc").split()[0]
    if shutil.which(compiler) is None:
        pytest.skip(f"no C compiler ({compiler}) on this machine")
