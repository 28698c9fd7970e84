/* parallel.c - vw_parallel: a serial phase split over a few threads (the pixel-ownership
 * map, the PNG's blocks). Part 0 runs on the calling thread; a part whose thread cannot
 * be started runs there too, so every part runs exactly once whatever happens.
 */
#include <pthread.h>

#include "vwalls/common.h"

typedef struct part {
    void (*fn)(int i, void *user);
    void *user;
    int i;
} part;

static void *run_part(void *arg)
{
    const part *p = arg;
    p->fn(p->i, p->user);
    return NULL;
}

void vw_parallel(int n, void (*fn)(int i, void *user), void *user)
{
    enum { MAX_THREADS = 64 };
    if (n > MAX_THREADS) { /* (callers split into at most as many parts as workers) */
        for (int i = 0; i < n; i++) fn(i, user);
        return;
    }
    part parts[MAX_THREADS];
    pthread_t th[MAX_THREADS];
    int started[MAX_THREADS] = {0};
    for (int i = 0; i < n; i++) parts[i] = (part){fn, user, i};
    for (int i = 1; i < n; i++) started[i] = pthread_create(&th[i], NULL, run_part, &parts[i]) == 0;
    if (n > 0) fn(0, user);
    for (int i = 1; i < n; i++) {
        if (started[i])
            pthread_join(th[i], NULL);
        else
            fn(i, user); /* no thread: this one runs the part */
    }
}
