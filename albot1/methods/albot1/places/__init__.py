"""Albot1's network of places (thesis chapter 4, Algorithms 5-8) on top of the chapter-3 perceptual map.

Exits (doorway-like gaps) are detected in views and tracked into the map
(:mod:`.exits`); crossing one closes the current place and opens the next
(:mod:`.memory`, Algorithm 5); a place re-visited is recognised by matching
its structure (:mod:`.matcher`, Algorithm 6); a recognised place's exits are
predicted in the perceptual map (:mod:`.navigation`, Algorithms 7-8); the
mapper :class:`~albot1.methods.albot1.places.mapper.Albot1PlacesMapper`
composes the chapter-3 mapper with all of it. ``docs/places.md`` documents
every reading of the thesis.
"""
