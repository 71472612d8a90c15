# Python module of jackal_aic's experiment tools (installed by catkin_python_setup()).
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=["jackal_aic_tools"], package_dir={"": "src"}))
