"""Capabilities: groups of robot operations, their registry, and the cells they run on."""
