"""Paper 1: Fuetterling, Lojewski and Pfreundt 2014, fqDel, the
floating-point quad-tree.  One module per figure or table it prints; each
declares its grid, its plot and its claims."""
PAPER = "Paper 1"
TITLE = "Paper 1: Fuetterling, Lojewski and Pfreundt 2014 (fqDel)"
# every result the paper prints, in its order
PUBLISHED = tuple(f"Fig. {k}" for k in (1, 3, 4, 5, 6, 7)) + ("Table 1",)
