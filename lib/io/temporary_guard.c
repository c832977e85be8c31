/* The temporary names a termination signal removes (see temporary_guard.h). A fixed table, so the
 * handler touches only static memory and calls only unlink, signal and raise, which are
 * async-signal-safe. */
#define _POSIX_C_SOURCE 200809L
#include "io/temporary_guard.h"

#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <string.h>
#include <unistd.h>

#define SLOTS 16
#define NAME_BYTES 4224

static char names[SLOTS][NAME_BYTES];
static volatile sig_atomic_t used[SLOTS];
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static int registered;

static const int guarded[3] = {SIGINT, SIGTERM, SIGHUP};
static struct sigaction previous[3];
static volatile sig_atomic_t caught[3]; /* ours is installed over previous[i] */

static void remove_names_and_chain(int signal_number, siginfo_t *info, void *context) {
    for (int i = 0; i < SLOTS; i++)
        if (used[i])
            unlink(names[i]);
    for (int i = 0; i < 3; i++) {
        if (guarded[i] != signal_number)
            continue;
        const struct sigaction *before = &previous[i];
        if (before->sa_flags & SA_SIGINFO) {
            before->sa_sigaction(signal_number, info, context);
        } else if (before->sa_handler == SIG_DFL) {
            signal(signal_number, SIG_DFL);
            raise(signal_number);
        } else if (before->sa_handler != SIG_IGN) {
            before->sa_handler(signal_number);
        }
    }
}

static bool is_ours(const struct sigaction *action) {
    return (action->sa_flags & SA_SIGINFO) && action->sa_sigaction == remove_names_and_chain;
}

static void catch_signals(void) {
    struct sigaction ours;
    memset(&ours, 0, sizeof ours);
    ours.sa_sigaction = remove_names_and_chain;
    ours.sa_flags = SA_SIGINFO;
    sigemptyset(&ours.sa_mask);
    for (int i = 0; i < 3; i++) {
        caught[i] = 0;
        if (sigaction(guarded[i], NULL, &previous[i]) != 0 || is_ours(&previous[i]) ||
            (!(previous[i].sa_flags & SA_SIGINFO) && previous[i].sa_handler == SIG_IGN))
            continue; /* an ignored signal (a background job's SIGINT) ends nothing */
        caught[i] = sigaction(guarded[i], &ours, NULL) == 0;
    }
}

static void release_signals(void) {
    for (int i = 0; i < 3; i++) {
        struct sigaction now;
        /* the previous action back only where ours is still there (the program may have moved on)
         */
        if (caught[i] && sigaction(guarded[i], NULL, &now) == 0 && is_ours(&now))
            sigaction(guarded[i], &previous[i], NULL);
        caught[i] = 0;
    }
}

int rs_guard_add(const char *path) {
    if (strlen(path) >= NAME_BYTES)
        return -1;
    pthread_mutex_lock(&lock);
    int slot = -1;
    for (int i = 0; i < SLOTS && slot < 0; i++)
        if (!used[i])
            slot = i;
    if (slot >= 0) {
        strcpy(names[slot], path);
        atomic_thread_fence(memory_order_seq_cst); /* the name is whole before it counts */
        used[slot] = 1;
        if (registered++ == 0)
            catch_signals();
    }
    pthread_mutex_unlock(&lock);
    return slot;
}

void rs_guard_remove(int slot) {
    if (slot < 0 || slot >= SLOTS)
        return;
    pthread_mutex_lock(&lock);
    if (used[slot]) {
        used[slot] = 0;
        if (--registered == 0)
            release_signals();
    }
    pthread_mutex_unlock(&lock);
}
