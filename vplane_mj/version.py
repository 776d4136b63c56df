"""The package's version and the version of the public contract it follows, in the one place
every layer may import them from."""

__version__ = "0.2.0"
CONTRACT_VERSION = "1.3"
"""The version of the public contract (docs/interface.md: scenario format, command line,
outputs, log topics) this package follows."""
