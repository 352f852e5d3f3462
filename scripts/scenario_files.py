"""What the scripts that rewrite CommonRoad scenarios share: the files a source names, and
writing each one's rewrite into an output directory (commonroad-transform.py,
commonroad-resample.py)."""
import os
import sys
import xml.etree.ElementTree as ET


def scenario_files(source, skip_solutions=False):
    """The .xml files of a directory (sorted), or the one file named; solution files left out
    when asked (a file whose name holds "solution")."""
    if os.path.isdir(source):
        files = sorted(os.path.join(source, f) for f in os.listdir(source) if f.endswith(".xml"))
    else:
        files = [source]
    if skip_solutions:
        files = [f for f in files if "solution" not in os.path.basename(f).lower()]
    return files


def rewrite_each(files, out_dir, rewrite):
    """rewrite(src, dst) for each file into out_dir under its own name; it returns False for a
    file it skips. Prints how many were written; 1 and the file's error at the first that fails
    to parse or write, else 0."""
    os.makedirs(out_dir, exist_ok=True)
    written = 0
    for f in files:
        try:
            written += rewrite(f, os.path.join(out_dir, os.path.basename(f))) is not False
        except (ET.ParseError, ValueError, OSError, AttributeError, TypeError, KeyError) as e:
            print(f"{f}: {e}", file=sys.stderr)
            return 1
    print(f"{written} files in {out_dir}")
    return 0
