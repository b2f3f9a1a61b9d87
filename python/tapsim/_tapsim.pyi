"""Type stubs of the extension module (python/src/lib.rs)."""

from typing import Any, Dict, List

__version__: str

def run(args: List[str]) -> Dict[str, Any]:
    """Run ``tapsim ARGS`` (``--json`` among them) in this process and return its
    document; ValueError with the command line's message where it refuses."""

def run_many(batch: List[List[str]]) -> List[Dict[str, Any]]:
    """Run several commands in parallel, in order; ValueError for the first refused."""
