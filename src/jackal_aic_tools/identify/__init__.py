"""Identification of the Jackal's MCU wheel loop for the simulated plant: the parameter search
(identify), from the robot's step responses (plant_identification) or from a robot's bag
(bag_identification, bag_fit; scripts/plant_identify.py), and the recorder that drives a Jackal
through the identification sequence (identification_recorder; scripts/record_identification.py)."""
