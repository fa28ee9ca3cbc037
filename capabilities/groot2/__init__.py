"""Groot2 watches a run: BehaviorTree.CPP's Groot2 publisher protocol over ZeroMQ.

:mod:`capabilities.groot2.protocol` encodes and decodes the messages (no sockets);
:mod:`capabilities.groot2.publisher` serves them for a running executor (imports pyzmq, so
import it only when publishing).
"""
