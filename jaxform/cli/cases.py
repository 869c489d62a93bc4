"""``jaxform cases``: list the preset forming cases, or print one as TOML to edit and run."""
from __future__ import annotations


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "cases",
        help="list the preset forming cases (jaxform cases NAME prints one as TOML)",
        description="List the preset hemisphere forming cases (SPEC section 4). With a NAME, print "
        "that preset as TOML: save it, edit it, and run it with 'jaxform run CASE.toml'.",
    )
    p.add_argument("name", nargs="?", help="a preset to print as TOML")
    p.set_defaults(handler=run)


def run(args) -> int:
    from jaxform import cases

    if getattr(args, "name", None):
        print(cases.to_toml(cases.preset(args.name)), end="")
        return 0
    presets = cases.list_presets()
    width = max(len(n) for n, _ in presets)
    for name, text in presets:
        print(f"{name:<{width}}  {text}")
    return 0
