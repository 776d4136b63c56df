"""vplane-mj: artificial potential fields and the virtual-plane escape from local minima in MuJoCo."""

import os
from importlib.metadata import PackageNotFoundError, version

# The tool runs headless: render offscreen with OSMesa unless the user chose a backend.
# Set before mujoco or dm_control import OpenGL, which would otherwise try GLFW and X11.
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])

try:
    __version__ = version("vplane-mj")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0"
