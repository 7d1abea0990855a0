"""Every file the README (and the experiments README) links, figures included, is in the
repository: checked against ``git ls-files`` where the checkout is a git clone (a file in the
working tree but ignored by .gitignore would pass a plain existence check and still be
missing for everyone else), else against the file system."""

import os
import re
import subprocess

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
READMES = ["README.md", "experiments/README.md", "docs/design.md", "docs/dask.md"]


def _links(readme):
    text = open(os.path.join(ROOT, readme), encoding="utf-8").read()
    base = os.path.dirname(readme)
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue                                   # web links and anchors
        yield os.path.normpath(os.path.join(base, target.split("#")[0]))


def _tracked():
    try:
        out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True,
                             check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    return set(out.splitlines()) or None


@pytest.mark.parametrize("readme", READMES)
def test_every_linked_file_is_in_the_repository(readme):
    links = sorted(set(_links(readme)))
    tracked = _tracked()
    missing = [p for p in links if (p not in tracked if tracked is not None
                                    else not os.path.exists(os.path.join(ROOT, p)))]
    assert not missing, f"{readme} links files that are not in the repository: {missing}"


def test_the_gallery_is_linked():
    links = list(_links("README.md"))
    assert "docs/dask.md" in links and "experiments/README.md" in links   # the parser works
    assert len([p for p in links if p.startswith("docs/figures/")]) >= 12


def _sources():
    tracked = _tracked() or []
    return [p for p in tracked if p.endswith((".py", ".md", ".toml")) and not p.startswith("docs/")]


def _headings(doc):
    text = open(os.path.join(ROOT, doc), encoding="utf-8").read()
    return set(re.findall(r"^#{2,4} (\d+(?:\.\d+)*)\.?\s", text, flags=re.M))


def test_every_docs_reference_points_at_a_section_that_exists():
    """References such as "docs/physics.md §8.6" or "§3.2–3.5, §4.4" name a file of the
    repository and numbered headings in it; every Markdown file any source names is a file of
    the repository (from the root or from the citing file's folder), so notes kept outside it
    are never cited."""
    sources = _sources()
    if not sources:
        pytest.skip("not a git checkout")
    tracked = _tracked()
    dead, outside = [], []
    for path in sources:
        text = open(os.path.join(ROOT, path), encoding="utf-8").read()
        for m in re.finditer(r"docs/([\w-]+\.md)((?:[ ,;]*§[\d.]+(?:[–-][\d.]+)?)*)", text):
            doc = "docs/" + m.group(1)
            if not os.path.exists(os.path.join(ROOT, doc)):
                dead.append(f"{path}: {m.group(0)}")
                continue
            heads = _headings(doc)
            for ref in re.findall(r"§([\d.]+)(?:[–-]([\d.]+))?", m.group(2)):
                for number in filter(None, ref):
                    if number.rstrip(".") not in heads:
                        dead.append(f"{path}: {m.group(0)} (no section {number})")
        for cited in re.findall(r"(?<![\w/.-])((?:\.\./|[\w-]+/)*[\w-]+\.md)\b", text):
            here = os.path.normpath(os.path.join(os.path.dirname(path), cited))
            if cited not in tracked and here not in tracked:
                outside.append(f"{path}: {cited}")
    assert not dead, dead
    assert not outside, outside
