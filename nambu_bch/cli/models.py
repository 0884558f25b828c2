"""``nambu-bch models``: the built-in systems (or the one chosen) and the pieces of their splittings."""

from __future__ import annotations

from ._options import add_subcommand, names_of, output_options, symbolic_system, system_options
from ._output import emit, once

HELP = "list the built-in systems and the pieces of their splittings"
EXAMPLES = ("examples:\n  nambu-bch models\n  nambu-bch models --model ho3 --format latex\n"
            "  nambu-bch models --H 'x2^2/2 + x1^4/4' --format json")


def register(sub) -> None:
    p = add_subcommand(sub, "models", HELP, EXAMPLES, run)
    system_options(p)
    output_options(p, "text")


def _strang(system) -> str:
    from ..integrators.composition import strang_word

    return strang_word(len(system.splitting))


def run(args):
    chosen = any(v is not None for v in (args.model, args.system, args.H, args.G, args.coords, args.param, args.split, args.bracket, args.name))

    @once
    def systems():
        from ..systems import model, model_names

        if chosen:
            return [symbolic_system(args)]
        return [model(name) for name in model_names()]

    def piece_dict(system, piece):
        from .. import render

        return {
            "number": piece.number,
            "label": piece.label(),
            "moves": [str(system.coordinates[i]) for i in piece.moving],
            "field": [render.expression(c) for c in piece.field.to_sympy()],
        }

    def data():
        from .. import render

        out = []
        for s in systems():
            d = render.system_dict(s)
            d.update(N=s.N, split=s.split, description=s.description, citation=s.citation,
                     pieces=[piece_dict(s, p) for p in s.splitting.pieces], default_integrator=_strang(s))
            out.append(d)
        return {"models": out}

    def text():
        lines = []
        for s in systems():
            lines.append(f"{s.name}  (N = {s.N}, bracket = {s.bracket}, split = {s.split}, default integrator {_strang(s)})")
            if s.description:
                lines.append(f"  {s.description}")
            lines.append(f"  coordinates: {names_of(s.coordinates)};  parameters: {names_of(s.parameters)}")
            for lab, H in zip(("H", "G", "H3", "H4"), s.hamiltonians):
                lines.append(f"  {lab} = {H}")
            for p in s.splitting.pieces:
                moves = ", ".join(str(s.coordinates[i]) for i in p.moving)
                comps = ", ".join(f"d{s.coordinates[i]}/dt = {p.field.to_sympy()[i]}" for i in p.moving)
                lines.append(f"  piece {p.number}: moves {moves}: {comps}")
            if s.citation:
                lines.append(f"  ref: {s.citation}")
        return "\n".join(lines)

    def latex():
        import sympy

        from ..printing import WIDTH, aligned, latex_text, sum_tokens, width

        def field_tokens(piece):
            # "X_{A,C} + ... = (c_1) d/dx_1 + ...": one token per Liouville term and per component (lines break between)
            labels = ["X_{" + ", ".join(sympy.latex(f) for f in term) + "}" for term in piece.terms]
            if any(width(lab) > WIDTH // 2 for lab in labels):  # a long Hamiltonian in a subscript cannot break
                labels = []
            tokens = labels[:1] + ["+ " + lab for lab in labels[1:]]
            parts = [rf"\left({sympy.latex(sympy.factor(c))}\right)\frac{{\partial}}{{\partial {sympy.latex(x)}}}"
                     for x, c in zip(piece.field.algebra.coordinates, piece.field.to_sympy()) if c != 0]
            head = ("= " if tokens else "") + (parts[0] if parts else "0")
            return tokens + [head] + ["+ " + part for part in parts[1:]]

        blocks = []
        for s in systems():
            coords = ", ".join(sympy.latex(x) for x in s.coordinates)  # the system named as in the text listing
            rows = [("", "", [latex_text(f"{s.name}: {s.bracket} bracket on") + rf"\ ({coords}):"])]
            labels = ["H", "G"] if len(s.hamiltonians) == 2 else [f"H_{{{k + 1}}}" for k in range(len(s.hamiltonians))]
            rows += [(lab, "=", sum_tokens(H)) for lab, H in zip(labels[: len(s.hamiltonians)] or ["H"], s.hamiltonians)]
            rows += [(f"X_{{{p.number}}}", "=", field_tokens(p)) for p in s.splitting.pieces]
            blocks.append(aligned(rows))
        return blocks

    emit(args, latex=latex, text=text, data=data, cache=None if chosen else ("models",))
