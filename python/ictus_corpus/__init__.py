"""ictus-corpus: labelled corpora of simulated drum performances on Dask (docs/corpus.md)."""
