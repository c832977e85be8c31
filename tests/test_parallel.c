/* The host stages' threads: a calling thread's setting (what rsmooth_context_options.host_threads
 * gives a context's calls) caps the chunks and the threads rs_parallel_for starts, is the calling
 * thread's alone, and is restored after; RSMOOTH_HOST_THREADS and the cores are the default. */
#include "core/rsmooth_internal.h"
#include "test_util.h"

#include <pthread.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#define MAX_SEEN 64

typedef struct seen {
    pthread_mutex_t lock;
    pthread_t ids[MAX_SEEN];
    size_t count;
} seen;

static void record(void *ctx, size_t begin, size_t end, size_t chunk) {
    (void)begin;
    (void)end;
    (void)chunk;
    seen *s = ctx;
    pthread_mutex_lock(&s->lock);
    pthread_t self = pthread_self();
    bool known = false;
    for (size_t i = 0; i < s->count; i++)
        known = known || pthread_equal(s->ids[i], self);
    if (!known && s->count < MAX_SEEN)
        s->ids[s->count++] = self;
    pthread_mutex_unlock(&s->lock);
}

static size_t threads_used(size_t count) {
    seen s;
    memset(&s, 0, sizeof s);
    pthread_mutex_init(&s.lock, NULL);
    rs_parallel_for(count, 1, record, &s);
    pthread_mutex_destroy(&s.lock);
    return s.count;
}

static void *other_thread(void *arg) {
    size_t *out = arg;
    *out = rs_host_threads(); /* not the main thread's setting */
    return NULL;
}

/* Each element written once, by the chunk that owns it; a chunk may run a loop of its own. */
typedef struct fill {
    unsigned char *hits;
    size_t count;
    bool nest;
} fill;

static void mark(void *ctx, size_t begin, size_t end, size_t chunk) {
    const fill *f = ctx;
    (void)chunk;
    for (size_t i = begin; i < end; i++)
        f->hits[i]++;
    if (f->nest && chunk == 0) {
        unsigned char inner[100] = {0};
        fill g = {inner, sizeof inner, false};
        rs_parallel_for(g.count, 1, mark, &g);
        for (size_t i = 0; i < g.count; i++)
            f->hits[f->count + i] = (unsigned char)(f->hits[f->count + i] + inner[i]);
    }
}

/* Loops of varying sizes, each element marked exactly once. */
static bool loops(size_t threads, bool nest) {
    enum { most = 5000 };
    static _Thread_local unsigned char hits[most + 100];
    rs_set_call_threads(threads);
    bool ok = true;
    for (size_t round = 0; round < 300 && ok; round++) {
        size_t count = (round * 37) % most;
        memset(hits, 0, sizeof hits);
        fill f = {hits, count, nest};
        rs_parallel_for(count, 1 + round % 7, mark, &f);
        for (size_t i = 0; i < count; i++)
            ok = ok && hits[i] == 1;
        for (size_t i = 0; nest && i < 100; i++)
            ok = ok && hits[count + i] == 1;
    }
    rs_set_call_threads(0);
    return ok;
}

static void *concurrent(void *arg) {
    size_t n = (size_t)(uintptr_t)arg;
    return loops(n % 4 + 2, n % 2 == 1) ? arg : NULL;
}

int main(void) {
    size_t before = rs_set_call_threads(3);
    CHECK_EQ_INT(before, 0);
    CHECK_EQ_INT(rs_host_threads(), 3);
    CHECK_EQ_INT(rs_parallel_chunks(1000, 1), 3);
    CHECK_EQ_INT(threads_used(1000), 3);
    pthread_t t;
    size_t elsewhere = 0;
    CHECK(pthread_create(&t, NULL, other_thread, &elsewhere) == 0);
    pthread_join(t, NULL);
    rs_set_call_threads(1);
    CHECK_EQ_INT(threads_used(1000), 1);
    CHECK_EQ_INT(rs_set_call_threads(500), 1);
    CHECK_EQ_INT(rs_host_threads(), 64); /* capped */
    rs_set_call_threads(0);
    /* the default: RSMOOTH_HOST_THREADS, else the cores; the other thread saw the default too */
    CHECK_EQ_INT(elsewhere, rs_host_threads());
    /* the pool: several threads at once (one has the pool, the others start their own threads),
     * loops inside a chunk, and a forked child with none of the parent's workers */
    CHECK(loops(4, false));
    enum { callers = 4 };
    pthread_t many[callers];
    for (size_t i = 0; i < callers; i++)
        CHECK(pthread_create(&many[i], NULL, concurrent, (void *)(uintptr_t)(i + 1)) == 0);
    for (size_t i = 0; i < callers; i++) {
        void *ret = NULL;
        pthread_join(many[i], &ret);
        CHECK(ret == (void *)(uintptr_t)(i + 1));
    }
    CHECK(loops(3, true));
#ifndef __SANITIZE_THREAD__ /* ThreadSanitizer does not follow a threaded process into fork */
    pid_t child = fork();
    CHECK(child >= 0);
    if (child == 0) {
        rs_set_call_threads(3);
        _exit(threads_used(1000) == 3 && loops(4, true) ? 0 : 1);
    }
    int status = 0;
    CHECK(waitpid(child, &status, 0) == child);
    CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0);
#endif
    rs_set_call_threads(3);
    CHECK_EQ_INT(threads_used(1000), 3);
    rs_set_call_threads(0);
    printf("parallel: a call's setting caps its threads (3, 1, capped at 64), other threads keep "
           "the default (%zu)\n",
           rs_host_threads());
    return 0;
}
