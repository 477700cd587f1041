"""The technique folders of analysis/techniques/<name>/: each technique declares its report sections
(section.py), README rows (headline.py) and documentation blocks (docs.py) in its own folder, and the
scripts that read them find them here, without a list.

    load(file_name) -> [(technique folder name, module)] for every analysis/techniques/*/<file_name>,
                       sorted by folder name
"""
import importlib.util
from pathlib import Path


def load(file_name):
    modules = []
    for path in sorted((Path(__file__).resolve().parent / "techniques").glob(f"*/{file_name}")):
        kind = file_name.removesuffix(".py")
        spec = importlib.util.spec_from_file_location(f"nbsim_{kind}_{path.parent.name}", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        modules.append((path.parent.name, module))
    return modules
