"""The Albot1 perceptual mapper (thesis 3.1.6-3.1.7 and Algorithm 4).

Localisation against recognised landmarks, the perceptual map with its
update rule, and the main loop behind the Mapper protocol. Views, landmarks
and recognition live in :mod:`albot1.methods.albot1.perception`.
"""
