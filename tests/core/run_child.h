/* run_child.h - a world run that should stop the process (a module's misuse aborts
 * it), made in a forked child with its stderr into a pipe: the child's wait status
 * comes back and its stderr in err (cap bytes, NUL-terminated). A child whose run
 * returns writes "the mistake went unnoticed" and exits 0. For test_misuse.c and
 * test_sized.c, which include <sys/wait.h> and <unistd.h> before it.
 */
#ifndef VW_TEST_RUN_CHILD_H
#define VW_TEST_RUN_CHILD_H

static int run_in_child(vw_world *w, char *err, size_t cap)
{
    int fd[2];
    CHECK(pipe(fd) == 0);
    fflush(NULL);
    pid_t pid = fork();
    CHECK(pid >= 0);
    if (pid == 0) {
        dup2(fd[1], 2);
        close(fd[0]);
        vw_world_run(w); /* the mistake stops the process in here */
        fprintf(stderr, "the mistake went unnoticed\n");
        _exit(0);
    }
    close(fd[1]);
    size_t n = 0;
    ssize_t k;
    while (n < cap - 1 && (k = read(fd[0], err + n, cap - 1 - n)) > 0) n += (size_t)k;
    err[n] = 0;
    close(fd[0]);
    int status = 0;
    CHECK(waitpid(pid, &status, 0) == pid);
    return status;
}

#endif
