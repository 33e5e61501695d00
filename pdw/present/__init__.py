"""Layer 5 -- presentation: figures, reports and the command line (docs/architecture.md).

plots    figures of one walk (the paper's Figs. 4-7) and its animation
report   the text report of a walk against the paper
cli      the ``pdw`` command (walk, run, sweep)

May import from every layer below; nothing imports it but `pdw.__main__`.
"""
