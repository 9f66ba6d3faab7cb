"""The project's LCM types (package `resolver`), looked up by fingerprint.

The classes themselves are generated at build time by `lcm-gen --python
--package-prefix resolver_lcm` from proto/resolver/*.lcm into
resolver_lcm.resolver (same fingerprints as the C++ and Java types: the
package name is not part of LCM's hash).
"""

from typing import Dict, Optional, Type

from . import resolver as _generated

FINGERPRINT_SIZE = 8  # [bytes] every encoded LCM message starts with its type's fingerprint


def _collect() -> Dict[bytes, Type]:
    by_fingerprint = {}
    for name in dir(_generated):
        cls = getattr(_generated, name)
        if isinstance(cls, type) and hasattr(cls, "_get_packed_fingerprint"):
            by_fingerprint[cls._get_packed_fingerprint()] = cls
    return by_fingerprint


TYPES_BY_FINGERPRINT: Dict[bytes, Type] = _collect()


def type_name(cls: Type) -> str:
    """'resolver.angle_t', as resolver-echo names it."""
    return "resolver." + cls.__name__


def find_type(data: bytes) -> Optional[Type]:
    """The generated class whose fingerprint starts `data`, or None."""
    return TYPES_BY_FINGERPRINT.get(bytes(data[:FINGERPRINT_SIZE]))


def fields(cls: Type):
    """Member names in declaration order."""
    return list(cls.__slots__)
