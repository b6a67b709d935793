//! The exit statuses of every command (README "Exit status", man pages' EXIT STATUS).
/// Everything asked for was done (in a batch: converted or up to date).
pub const OK: i32 = 0;
/// Something the command read or wrote failed (in a batch: at least one input; the
/// others were still converted).
pub const FAILED: i32 = 1;
/// The command line cannot work for any input: an unknown option or value, a colour
/// space or OCIO config that cannot be used, a missing output directory, a model that
/// cannot be read. Checked before the first input; nothing was written.
pub const USAGE: i32 = 2;
/// Stopped by SIGINT or SIGTERM; no partial output was left.
pub const INTERRUPTED: i32 = 130;
/// Standard output was closed before the command was done (`| head -1`): 128 + SIGPIPE,
/// what a shell reports for a process SIGPIPE killed. The input being converted was
/// finished or left as it was; no other was started.
pub const PIPE: i32 = 141;
/// The table as the README and the man pages print it.
pub const TABLE: [(i32, &str); 5] = [
    (OK, "everything asked for was done (in a batch: every input converted, up to date, or a data texture skipped or written through by --data)"),
    (
        FAILED,
        "an input, output or other file failed (in a batch: at least one input failed; the others were converted)",
    ),
    (
        USAGE,
        "the command line cannot work for any input: an unknown option or value, a colour space or OCIO config that cannot be used, a missing output directory, an unreadable model; checked before the first input, nothing written",
    ),
    (INTERRUPTED, "interrupted by SIGINT or SIGTERM; no partial output left"),
    (
        PIPE,
        "standard output was closed (a reader such as `head` stopped reading): the command stopped quietly; the input being converted was finished or left as it was, no other was started",
    ),
];
