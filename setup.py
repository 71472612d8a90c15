# Python module of jackal_aic's tools (installed by catkin_python_setup()): the package and its
# subpackages (src/jackal_aic_tools/__init__.py says what each holds).
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(
    packages=["jackal_aic_tools", "jackal_aic_tools.common", "jackal_aic_tools.compare", "jackal_aic_tools.experiment",
              "jackal_aic_tools.field", "jackal_aic_tools.identify", "jackal_aic_tools.reproduce",
              "jackal_aic_tools.robustness", "jackal_aic_tools.track", "jackal_aic_tools.tune"],
    package_dir={"": "src"}))
