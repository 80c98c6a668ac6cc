"""Albot1's perception (thesis 3.1.3-3.1.5): views, landmarks and their recognition.

Pure maths on one scan or one pair of views, in the thesis frame (robot at
the origin facing +y, surfaces left to right); no I/O and no map state.
"""
