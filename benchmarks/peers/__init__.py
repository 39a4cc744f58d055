"""Peer comparisons (OpenSees, a C++ CPU bound): ``python -m femast.benchmarks.peers.NAME``."""
