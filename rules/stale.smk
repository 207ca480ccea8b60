# `snakemake remove_stale`: the folders and files of runs taken out of the config
# (STALE, named at the start of every run), never part of `all`
rule remove_stale:
    log:
        "results/logs/remove_stale.log",
    run:
        Path(log[0]).write_text("".join(f"removed {p}\n" for p in STALE))
        remove(STALE)
