/* Names of temporary files that a termination signal must not leave behind (not installed).
 *
 * While at least one name is registered, SIGINT, SIGTERM and SIGHUP (unless ignored) are caught:
 * the handler removes every registered name, then does what the previous action would have done:
 * the default action ends the process as the signal would have (restored and raised again), a
 * handler of the program's (or of a library such as PoCL, which cleans up its own files and ends
 * the process) is called with the same arguments. So the process ends as it would have, minus the
 * files; a handler that lets it go on (Python's SIGINT) finds the temporary gone, and the write
 * fails instead of completing. The previous actions come back when the last name goes. SIGKILL
 * cannot be caught: what it leaves is named ".rsmooth-*" beside the output. */
#ifndef RSMOOTH_TEMPORARY_GUARD_H
#define RSMOOTH_TEMPORARY_GUARD_H

/* Registers `path` (copied); returns its slot, or -1 when the table is full (the file is then
 * written unguarded) or the path too long. Thread-safe. */
int rs_guard_add(const char *path);

/* Forgets the slot's name (after the file was renamed, linked or removed). -1 is ignored. */
void rs_guard_remove(int slot);

#endif
