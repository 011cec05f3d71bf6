"""One interactive explorer per notebook, each built on a plain drawing function."""
