"""The ``albot1`` command line (Typer). Thin: parsing and printing only."""
