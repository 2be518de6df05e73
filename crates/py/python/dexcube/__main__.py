"""``python -m dexcube`` runs the benchmark (``dexcube.bench``)."""

from .bench import main

main()
