"""MRPT rawlog files (write only): the input of MRPT's SLAM applications."""
