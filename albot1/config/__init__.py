"""Configs of every method, and the small parsers every layer above shares.

``presets`` (TOML preset files), ``method_model`` (the base of every
method's config: strict and finite), ``env`` (``ALBOT1_<METHOD>_<FIELD>``
variables), ``resolve`` (the precedence model < preset < env < ``--set``),
``describe`` (fields, units and preset changes for listings), ``keyvalue``
(the one ``KEY=VALUE`` parser), ``validation`` (the one wording of pydantic
errors), ``targets`` (the one ``module:Class`` resolver). See
``docs/architecture.md``, "Configs and presets".
"""
