"""The one way the report scripts save a figure."""


def save_figure(fig, path, dpi=110):
    """Lay the figure out tightly, write it to path (PNG at dpi) and close it."""
    import matplotlib.pyplot as plt
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def pyplot():
    """matplotlib's pyplot drawing to files only (the Agg backend), for scripts run without a display."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt
