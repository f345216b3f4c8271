"""deckgen: bonded-particle DEM decks for rock-cutting studies.

Data flows one way: spec -> packing -> deck -> run -> parse -> tables -> analysis.
"""

__version__ = "0.1.0"
