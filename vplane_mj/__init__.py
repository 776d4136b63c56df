"""vplane-mj: artificial potential fields and the virtual-plane escape from local minima in MuJoCo."""

import os

__version__ = "0.1.0"

# The tool runs headless: render offscreen with OSMesa unless the user chose a backend.
# Set before mujoco imports OpenGL, which would otherwise try GLFW and X11.
GL_CHOSEN_BY_USER = "MUJOCO_GL" in os.environ
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])
