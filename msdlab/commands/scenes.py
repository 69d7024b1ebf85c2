"""``msdlab scenes``: list the scenes, or show one scene's settings and their defaults."""

from __future__ import annotations

import argparse

from ..scenes import SCENES, get_scene


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "scenes",
        help="list the scenes (one line each), or the settings of one scene",
        description=__doc__,
    )
    parser.add_argument(
        "name", nargs="?", help="a scene whose settings (for `msdlab run --set`) to show"
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    if args.name is None:
        width = max(len(name) for name in SCENES)
        for scene in SCENES.values():
            print(f"{scene.name:<{width}}  {scene.description}")
        return 0
    scene = get_scene(args.name)
    print(f"{scene.name}: {scene.description}")
    print(f"runs for {scene.duration:g} {scene.unit} by default; settings (--set key=value):")
    for key, value in scene.settings().items():
        print(f"  {key} = {value!r}")
    return 0
