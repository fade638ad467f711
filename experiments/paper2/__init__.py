"""Paper 2: Liu, Yan and Lo 2013, the Kd-tree insertion order.  One module
per group of tables (liu_times: Tables 1-7, liu_counts: 8-14, ...), and
liu.py for its models, orders, sizes and published values."""
PAPER = "Paper 2"
TITLE = "Paper 2: Liu, Yan and Lo 2013 (Kd-tree insertion order)"
# every result the paper prints, in its order
PUBLISHED = tuple(f"Table {k}" for k in range(1, 18))
