/* test_io_outfile.c - vw_outfile (vwalls/outfile.h): what each kind of name becomes (a
 * new or regular file replaced whole; a symbolic link kept, the file it leads to
 * written; a device or a FIFO written in place and left what it was; a dangling link, a
 * directory and an empty name refused), the mode under the umask, that no failure
 * leaves a temporary file, that vw_outfile_remove_temps() in a SIGTERM handler
 * leaves none behind whatever the writing threads were doing when the signal came, and
 * that vw_outfile_check refuses what the open would, writing nothing, and that held
 * commits appear together or not at all.
 * Usage: test_io_outfile   (the device checks need CAP_MKNOD and are skipped without it)
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "io_test_util.h"
#include "vw_test.h"
#include "vwalls/outfile.h"

static char dir[64];

static const char *at(const char *name)
{
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

/* Names holding ".tmp." under d (one level): temporary files. Printed unless
   expected (the checks that expect some say so: temps_expected). */
static int temps_expected;
static int temps_in(const char *d)
{
    DIR *dp = opendir(d);
    CHECK(dp != NULL);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(dp)))
        if (strstr(e->d_name, ".tmp.")) {
            if (!temps_expected) fprintf(stderr, "left behind: %s/%s\n", d, e->d_name);
            n++;
        }
    closedir(dp);
    return n;
}

static char *text_of(const char *p)
{
    FILE *f = fopen(p, "rb");
    if (!f) return NULL;
    static char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = 0;
    fclose(f);
    return buf;
}

static vw_status put(const char *path, const char *text, char *err, size_t errlen)
{
    err[0] = 0;
    return vw_outfile_write(path, text, strlen(text), err, errlen);
}

static mode_t mode_of(const char *p)
{
    struct stat st;
    CHECK(lstat(p, &st) == 0);
    return st.st_mode;
}

static void regular_files(void)
{
    char err[512];
    mode_t old = umask(022);
    CHECK_EQ_INT(put(at("a.txt"), "one\n", err, sizeof err), VW_OK);
    CHECK(strcmp(text_of(at("a.txt")), "one\n") == 0);
    CHECK_EQ_INT(mode_of(at("a.txt")) & 07777, 0644);
    /* Replaced whole, with the mode the umask in force then gives. */
    umask(077);
    CHECK_EQ_INT(put(at("a.txt"), "two\n", err, sizeof err), VW_OK);
    CHECK(strcmp(text_of(at("a.txt")), "two\n") == 0);
    CHECK_EQ_INT(mode_of(at("a.txt")) & 07777, 0600);
    umask(022);
    CHECK_EQ_INT(put(at("a.txt"), "three\n", err, sizeof err), VW_OK);
    CHECK_EQ_INT(mode_of(at("a.txt")) & 07777, 0644);
    umask(old);

    /* Abort: nothing under the name, the old file untouched. */
    vw_outfile *f;
    CHECK_EQ_INT(vw_outfile_open(at("a.txt"), &f, err, sizeof err), VW_OK);
    fputs("partial", vw_outfile_stream(f));
    fflush(vw_outfile_stream(f));
    temps_expected = 1;
    CHECK_EQ_INT(temps_in(dir), 1);
    temps_expected = 0;
    vw_outfile_abort(f);
    CHECK(strcmp(text_of(at("a.txt")), "three\n") == 0);
    CHECK_EQ_INT(vw_outfile_open(at("new.txt"), &f, err, sizeof err), VW_OK);
    vw_outfile_abort(f);
    CHECK(access(at("new.txt"), F_OK) != 0);
    vw_outfile_abort(NULL);
    CHECK(vw_outfile_stream(NULL) == NULL);

    /* A write that fails (the file size limit, as a full disk would): an error with its
       reason, and neither the file nor a temporary one. */
    struct rlimit rl;
    CHECK(file_size_limit(1000, &rl) == 0);
    char big[5000];
    memset(big, 'x', sizeof big);
    vw_status st = vw_outfile_write(at("big.txt"), big, sizeof big, err, sizeof err);
    CHECK(file_size_restore(&rl) == 0);
    printf("too large: %s\n", err);
    CHECK_EQ_INT(st, VW_E_IO);
    CHECK(strstr(err, "big.txt: write failed: ") != NULL);
    CHECK(access(at("big.txt"), F_OK) != 0);

    /* Empty names and directories are refused; the directory is left alone. */
    CHECK_EQ_INT(put("", "x", err, sizeof err), VW_E_INVAL);
    CHECK(strstr(err, "empty file name") != NULL);
    CHECK(mkdir(at("d"), 0755) == 0);
    CHECK_EQ_INT(put(at("d"), "x", err, sizeof err), VW_E_IO);
    printf("directory: %s\n", err);
    CHECK(strstr(err, "Is a directory") != NULL);
    CHECK(S_ISDIR(mode_of(at("d"))));
    CHECK_EQ_INT(temps_in(dir), 0);
    /* No buffer for a length: refused, the file as it was (fwrite read from NULL). */
    CHECK_EQ_INT(vw_outfile_write(at("a.txt"), NULL, 5, err, sizeof err), VW_E_INVAL);
    CHECK(strstr(err, "a.txt: no data") != NULL);
    CHECK(strcmp(text_of(at("a.txt")), "three\n") == 0);
    CHECK_EQ_INT(vw_outfile_write(at("empty.txt"), NULL, 0, err, sizeof err), VW_OK);
    CHECK(strcmp(text_of(at("empty.txt")), "") == 0);
    CHECK_EQ_INT(temps_in(dir), 0);
}

static void symbolic_links(void)
{
    char err[512], buf[256];
    CHECK(mkdir(at("sub"), 0755) == 0);
    CHECK_EQ_INT(put(at("real.txt"), "old\n", err, sizeof err), VW_OK);
    /* A relative link from another directory, and a link to that link. */
    CHECK(symlink("../real.txt", at("sub/link.txt")) == 0);
    CHECK(symlink("sub/link.txt", at("chain.txt")) == 0);
    CHECK_EQ_INT(put(at("sub/link.txt"), "via link\n", err, sizeof err), VW_OK);
    CHECK(S_ISLNK(mode_of(at("sub/link.txt"))));
    ssize_t n = readlink(at("sub/link.txt"), buf, sizeof buf - 1);
    CHECK(n == 11 && memcmp(buf, "../real.txt", 11) == 0);
    CHECK(S_ISREG(mode_of(at("real.txt"))));
    CHECK(strcmp(text_of(at("real.txt")), "via link\n") == 0);
    CHECK_EQ_INT(put(at("chain.txt"), "via chain\n", err, sizeof err), VW_OK);
    CHECK(S_ISLNK(mode_of(at("chain.txt"))) && S_ISLNK(mode_of(at("sub/link.txt"))));
    CHECK(strcmp(text_of(at("real.txt")), "via chain\n") == 0);
    CHECK_EQ_INT(temps_in(dir), 0);
    CHECK_EQ_INT(temps_in(at("sub")), 0);

    /* A dangling link is refused, and nothing is created where it points. */
    CHECK(symlink("missing.txt", at("dangling.txt")) == 0);
    CHECK_EQ_INT(put(at("dangling.txt"), "x", err, sizeof err), VW_E_IO);
    printf("dangling: %s\n", err);
    CHECK(strstr(err, "dangling.txt: is a symbolic link to a file that does not exist") != NULL);
    CHECK(S_ISLNK(mode_of(at("dangling.txt"))));
    CHECK(access(at("missing.txt"), F_OK) != 0);
    /* A link to a directory is a directory. */
    CHECK(symlink("d", at("dirlink")) == 0);
    CHECK_EQ_INT(put(at("dirlink"), "x", err, sizeof err), VW_E_IO);
    CHECK(strstr(err, "Is a directory") != NULL);
    CHECK(S_ISLNK(mode_of(at("dirlink"))));
    CHECK_EQ_INT(temps_in(dir), 0);
}

static void *drain(void *arg)
{
    int fd = open((const char *)arg, O_RDONLY);
    size_t total = 0;
    char buf[4096];
    ssize_t k;
    while (fd >= 0 && (k = read(fd, buf, sizeof buf)) > 0) total += (size_t)k;
    if (fd >= 0) close(fd);
    return (void *)total;
}

static void special_files(void)
{
    char err[512];
    /* A FIFO: written in place (a reader gets every byte) and still a FIFO. */
    CHECK(mkfifo(at("fifo"), 0644) == 0);
    pthread_t reader;
    CHECK(pthread_create(&reader, NULL, drain, (void *)at("fifo")) == 0);
    static char data[200000];
    memset(data, 'y', sizeof data);
    CHECK_EQ_INT(vw_outfile_write(at("fifo"), data, sizeof data, err, sizeof err), VW_OK);
    /* (Before the join: had the FIFO been replaced, the reader would wait for ever.) */
    CHECK(S_ISFIFO(mode_of(at("fifo"))));
    void *got;
    pthread_join(reader, &got);
    CHECK_EQ_INT((size_t)got, sizeof data);

    /* Copies of /dev/null and /dev/full made here (the real ones are left alone). */
    if (mknod(at("null"), S_IFCHR | 0666, makedev(1, 3)) != 0) {
        printf("devices skipped: mknod: %s\n", strerror(errno));
        CHECK_EQ_INT(temps_in(dir), 0);
        return;
    }
    CHECK(mknod(at("full"), S_IFCHR | 0666, makedev(1, 7)) == 0);
    CHECK(symlink("null", at("nulllink")) == 0);
    CHECK_EQ_INT(vw_outfile_write(at("null"), data, sizeof data, err, sizeof err), VW_OK);
    CHECK_EQ_INT(vw_outfile_write(at("nulllink"), data, 10, err, sizeof err), VW_OK);
    struct stat st;
    CHECK(stat(at("null"), &st) == 0 && S_ISCHR(st.st_mode) && st.st_rdev == makedev(1, 3));
    CHECK(S_ISLNK(mode_of(at("nulllink"))));
    vw_status s = vw_outfile_write(at("full"), data, sizeof data, err, sizeof err);
    printf("full: %s\n", err);
    CHECK_EQ_INT(s, VW_E_IO);
    CHECK(strstr(err, "full: write failed: No space left on device") != NULL);
    CHECK(stat(at("full"), &st) == 0 && S_ISCHR(st.st_mode) && st.st_rdev == makedev(1, 7));
    CHECK_EQ_INT(temps_in(dir), 0);
}

/* More files open at once than the registry holds: the rest are written all the same. */
static void many_at_once(void)
{
    char err[512], name[64];
    CHECK(mkdir(at("many"), 0755) == 0);
    vw_outfile *f[80];
    for (int i = 0; i < 80; i++) {
        snprintf(name, sizeof name, "many/%02d.txt", i);
        CHECK_EQ_INT(vw_outfile_open(at(name), &f[i], err, sizeof err), VW_OK);
        fprintf(vw_outfile_stream(f[i]), "%d\n", i);
    }
    temps_expected = 1;
    CHECK_EQ_INT(temps_in(at("many")), 80);
    temps_expected = 0;
    for (int i = 0; i < 80; i++) CHECK_EQ_INT(vw_outfile_commit(f[i], err, sizeof err), VW_OK);
    CHECK_EQ_INT(temps_in(at("many")), 0);
    CHECK(strcmp(text_of(at("many/79.txt")), "79\n") == 0);
}

/* ---- SIGTERM while threads write: the handler leaves no temporary file ------------- */

static const char *sig_dir;

static void on_term(int sig)
{
    vw_outfile_remove_temps();
    signal(sig, SIG_DFL);
    raise(sig);
}

/* Opens, writes, commits or aborts, as fast as it can: every step of the registry
   is in flight at some moment. */
static void *writer(void *arg)
{
    long id = (long)arg;
    char path[512], err[512], block[3000];
    memset(block, 'z', sizeof block);
    for (unsigned i = 0;; i++) {
        snprintf(path, sizeof path, "%s/w%ld-%u.txt", sig_dir, id, i % 4);
        vw_outfile *f;
        if (vw_outfile_open(path, &f, err, sizeof err) != VW_OK) continue;
        fwrite(block, 1, (i % 5) * sizeof block / 4, vw_outfile_stream(f));
        if (i % 3 == 2)
            vw_outfile_abort(f);
        else
            vw_outfile_commit(f, err, sizeof err);
    }
    return NULL;
}

static void signal_rounds(void)
{
    CHECK(mkdir(at("sig"), 0755) == 0);
    sig_dir = at("sig");
    srand((unsigned)time(NULL));
    int pending_seen = 0;
    for (int round = 0; round < 40; round++) {
        int ready[2];
        CHECK(pipe(ready) == 0);
        pid_t pid = fork();
        CHECK(pid >= 0);
        if (pid == 0) {
            signal(SIGTERM, on_term);
            pthread_t t[4];
            for (long k = 0; k < 4; k++) pthread_create(&t[k], NULL, writer, (void *)k);
            char c = 1;
            if (write(ready[1], &c, 1) != 1) _exit(3);
            pthread_join(t[0], NULL);
            _exit(4);
        }
        close(ready[1]);
        char c;
        CHECK(read(ready[0], &c, 1) == 1);
        close(ready[0]);
        struct timespec ts = {0, (long)(1 + rand() % 20) * 1000000L};
        nanosleep(&ts, NULL);
        DIR *dp = opendir(sig_dir);
        struct dirent *e;
        while (dp && (e = readdir(dp)))
            pending_seen += strstr(e->d_name, ".tmp.") != NULL;
        if (dp) closedir(dp);
        CHECK(kill(pid, SIGTERM) == 0);
        int status;
        CHECK(waitpid(pid, &status, 0) == pid);
        CHECK(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM);
        CHECK_EQ_INT(temps_in(sig_dir), 0);
    }
    /* The writers had temporary files open when looked at: the signals met some. */
    printf("signal rounds: 40, temporary files seen while writing: %d\n", pending_seen);
    CHECK(pending_seen > 0);
}

/* Last: afterwards this process may write no more files. */
static void remove_temps_ends_writing(void)
{
    char err[512];
    vw_outfile *f;
    CHECK_EQ_INT(vw_outfile_open(at("late.txt"), &f, err, sizeof err), VW_OK);
    fputs("late\n", vw_outfile_stream(f));
    temps_expected = 1;
    CHECK_EQ_INT(temps_in(dir), 1);
    temps_expected = 0;
    vw_outfile_remove_temps();
    CHECK_EQ_INT(temps_in(dir), 0);
    CHECK_EQ_INT(vw_outfile_commit(f, err, sizeof err), VW_E_STATE);
    CHECK(access(at("late.txt"), F_OK) != 0);
    CHECK_EQ_INT(put(at("later.txt"), "x", err, sizeof err), VW_E_STATE);
    CHECK(strstr(err, "the process is ending") != NULL);
    CHECK(access(at("later.txt"), F_OK) != 0);
}

/* vw_outfile_check: what the open would refuse, refused without writing anything. */
static void checks(void)
{
    char err[512];
    /* a new name: allowed, and nothing made */
    CHECK_EQ_INT(vw_outfile_check(at("chk-new.txt"), err, sizeof err), VW_OK);
    CHECK(access(at("chk-new.txt"), F_OK) != 0);
    /* a regular file: allowed, and left as it was */
    CHECK_EQ_INT(put(at("chk-old.txt"), "kept", err, sizeof err), VW_OK);
    CHECK_EQ_INT(vw_outfile_check(at("chk-old.txt"), err, sizeof err), VW_OK);
    CHECK(strcmp(text_of(at("chk-old.txt")), "kept") == 0);
    /* a link to a regular file: allowed; a dangling one, or one into a directory nobody
       can create files in (/proc, even as root): refused with the open's message */
    CHECK(symlink(at("chk-old.txt"), at("chk-link.txt")) == 0);
    CHECK_EQ_INT(vw_outfile_check(at("chk-link.txt"), err, sizeof err), VW_OK);
    CHECK(symlink(at("nodir/x.txt"), at("chk-dangling.txt")) == 0);
    CHECK_EQ_INT(vw_outfile_check(at("chk-dangling.txt"), err, sizeof err), VW_E_IO);
    EXPECT(strstr(err, "chk-dangling.txt: is a symbolic link to a file that does not exist"),
           "dangling link: '%s'", err);
    CHECK(symlink("/proc/version", at("chk-proc.txt")) == 0);
    CHECK_EQ_INT(vw_outfile_check(at("chk-proc.txt"), err, sizeof err), VW_E_IO);
    EXPECT(strstr(err, "chk-proc.txt: cannot create:"), "link into /proc: '%s'", err);
    CHECK(strstr(text_of("/proc/version"), "Linux") != NULL);
    /* a missing directory, a directory: refused */
    CHECK_EQ_INT(vw_outfile_check(at("nodir/x.txt"), err, sizeof err), VW_E_IO);
    CHECK_EQ_INT(vw_outfile_check(dir, err, sizeof err), VW_E_IO);
    /* a device: allowed and not written; a FIFO without a reader: allowed at once (the
       open would wait for a reader) */
    CHECK_EQ_INT(vw_outfile_check("/dev/null", err, sizeof err), VW_OK);
    CHECK(mkfifo(at("chk-fifo"), 0600) == 0);
    CHECK_EQ_INT(vw_outfile_check(at("chk-fifo"), err, sizeof err), VW_OK);
    CHECK_EQ_INT(temps_in(dir), 0);
    CHECK(unlink(at("chk-fifo")) == 0);
}

/* vw_outfile_hold / vw_outfile_release: held commits appear together, in order, or
   not at all; a file written in place is not held. */
static void held(void)
{
    char err[512];
    CHECK_EQ_INT(put(at("held-a.txt"), "old a", err, sizeof err), VW_OK);
    /* released with 0: none of them, and the old file as it was */
    vw_outfile_hold();
    CHECK_EQ_INT(put(at("held-a.txt"), "new a", err, sizeof err), VW_OK);
    CHECK_EQ_INT(put(at("held-b.txt"), "new b", err, sizeof err), VW_OK);
    CHECK(strcmp(text_of(at("held-a.txt")), "old a") == 0);
    CHECK(access(at("held-b.txt"), F_OK) != 0);
    temps_expected = 1;
    CHECK_EQ_INT(temps_in(dir), 2); /* complete, waiting */
    temps_expected = 0;
    CHECK_EQ_INT(vw_outfile_release(0, err, sizeof err), VW_OK);
    CHECK(strcmp(text_of(at("held-a.txt")), "old a") == 0);
    CHECK(access(at("held-b.txt"), F_OK) != 0);
    CHECK_EQ_INT(temps_in(dir), 0);
    /* released with 1: all of them; /dev/null, written in place, is not held */
    vw_outfile_hold();
    CHECK_EQ_INT(put(at("held-a.txt"), "new a", err, sizeof err), VW_OK);
    CHECK_EQ_INT(put("/dev/null", "nothing", err, sizeof err), VW_OK);
    CHECK_EQ_INT(put(at("held-b.txt"), "new b", err, sizeof err), VW_OK);
    CHECK_EQ_INT(vw_outfile_release(1, err, sizeof err), VW_OK);
    CHECK(strcmp(text_of(at("held-a.txt")), "new a") == 0);
    CHECK(strcmp(text_of(at("held-b.txt")), "new b") == 0);
    CHECK_EQ_INT(temps_in(dir), 0);
    /* the hold ended with the release: the next commit is in place at once */
    CHECK_EQ_INT(put(at("held-b.txt"), "newer b", err, sizeof err), VW_OK);
    CHECK(strcmp(text_of(at("held-b.txt")), "newer b") == 0);
    /* a failed write is not held, and says why at its commit */
    if (access("/dev/full", W_OK) != 0) return;
    vw_outfile_hold();
    CHECK_EQ_INT(put("/dev/full", "lost", err, sizeof err), VW_E_IO);
    EXPECT(strstr(err, "No space left on device"), "/dev/full: '%s'", err);
    CHECK_EQ_INT(vw_outfile_release(1, err, sizeof err), VW_OK);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/vw_outfile_XXXXXX");
    CHECK(mkdtemp(dir) != NULL);
    regular_files();
    symbolic_links();
    special_files();
    many_at_once();
    signal_rounds();
    checks();
    held();
    remove_temps_ends_writing(); /* last: no vw_outfile opens after it */
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
    TEST_DONE();
}
