/* test_cli_fulldisk.c -- issue 33, item 1: render, study and convergence
 * on a full disk.  gnuplot reports no failed write: before the fix render
 * renamed a cut-off PNG onto the old one with exit status 0, study left an
 * invalid curvature.png, convergence exited 0 with cut-off figures.  Now
 * each exits 1 and no cut-off picture is left (render's old file intact).
 *
 * The disk is a small tmpfs mounted in a private mount namespace (the test
 * process's own, so nothing is seen outside it and the mount ends with
 * the process): root, or an unprivileged user namespace, is needed.
 * Where neither is allowed, or gnuplot is missing, the suite reports a
 * skip (77) with the reason. */
#define _GNU_SOURCE
#include <check.h>
#include <errno.h>
#include <sched.h>
#include <sys/mount.h>

#include "jf_test.h"
#include "test_cli_util.h"

static char disk[300]; /* the tmpfs */

/* Fills the tmpfs, then frees `room` bytes: the next big write fails. */
static void fill_leaving(size_t room)
{
    char p[400];
    snprintf(p, sizeof p, "%s/filler", disk);
    int fd = open(p, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ck_assert_int_ge(fd, 0);
    static char block[4096];
    size_t total = 0;
    for (ssize_t w; (w = write(fd, block, sizeof block)) > 0;) total += (size_t)w;
    ck_assert_uint_gt(total, room);
    ck_assert_int_eq(ftruncate(fd, (off_t)(total - room)), 0);
    close(fd);
}

/* Every ".png" in dir is whole, and no temporary is left; returns how
 * many PNGs there are. */
static int pngs_whole(const char *dir)
{
    int n = 0;
    DIR *d = opendir(dir);
    ck_assert_ptr_nonnull(d);
    for (struct dirent *e; (e = readdir(d));) {
        size_t l = strlen(e->d_name);
        char p[700];
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        ck_assert_msg(!(e->d_name[0] == '.' && l > 4 && !strcmp(e->d_name + l - 4, ".tmp")),
                      "temporary left: %s", e->d_name);
        if (l > 4 && !strcmp(e->d_name + l - 4, ".png")) {
            ck_assert_msg(cli_whole_png(p), "%s is cut off", p);
            n++;
        }
    }
    closedir(d);
    return n;
}

static void setup(void)
{
    cli_setup();
    /* a fresh 1 MiB disk for each test */
    umount2(disk, MNT_DETACH);
    ck_assert_int_eq(mount("jf_full", disk, "tmpfs", 0, "size=1m,mode=0777"), 0);
}

static void teardown(void)
{
    umount2(disk, MNT_DETACH);
    fflush(NULL);
    pid_t p = fork();
    if (p == 0) {
        execl("/bin/rm", "rm", "-rf", cli_dir, (char *)NULL);
        _exit(127);
    }
    waitpid(p, NULL, 0);
}

/* render: the old picture stays, exit 1, one line (before: rc 0 and a
 * cut-off PNG in its place). */
START_TEST(render_full_disk)
{
    const char *pts = cli_path("s.ply"), *res = cli_path("s.csv");
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "20000", "-o", pts, NULL), 0);
    ck_assert_int_eq(cli_run("estimate", pts, "-o", res, "--quiet", NULL), 0);
    char png[400];
    snprintf(png, sizeof png, "%s/pic.png", disk);
    ck_assert_int_eq(cli_run("render", res, "-o", png, NULL), 0); /* room: a whole one */
    ck_assert(cli_whole_png(png));
    struct stat old;
    ck_assert_int_eq(stat(png, &old), 0);
    ck_assert_uint_gt(old.st_size, 3 * 8192);
    fill_leaving(8192);
    ck_assert_int_eq(cli_run("render", res, "-o", png, NULL), 1);
    ck_assert_msg(strstr(cli_err, "pic.png") && strchr(cli_err, '\n') == strrchr(cli_err, '\n'),
                  "not one line naming the file: %s", cli_err);
    struct stat now;
    ck_assert_int_eq(stat(png, &now), 0);
    ck_assert(now.st_ino == old.st_ino && now.st_size == old.st_size && cli_whole_png(png));
    ck_assert_int_eq(pngs_whole(disk), 1);
}
END_TEST

/* study: exit 1, no cut-off picture (before: an invalid curvature.png). */
START_TEST(study_full_disk)
{
    char dir[400];
    snprintf(dir, sizeof dir, "%s/st", disk);
    ck_assert_int_eq(mkdir(dir, 0777), 0);
    fill_leaving(24 * 1024);
    int rc = cli_run("study", "exp", "-o", dir, "--n", "600", "--neighbors", "knn:12;knn:24",
                     "--noise", "0;0.01", "--quiet", NULL);
    ck_assert_msg(rc == 1, "rc %d: %s", rc, cli_err);
    pngs_whole(dir);
}
END_TEST

/* convergence: exit 1, no cut-off figure (before: rc 0, figures cut). */
START_TEST(convergence_full_disk)
{
    char dir[400];
    snprintf(dir, sizeof dir, "%s/cv", disk);
    ck_assert_int_eq(mkdir(dir, 0777), 0);
    fill_leaving(48 * 1024);
    int rc = cli_run("convergence", "--out", dir, "--quick", NULL);
    ck_assert_msg(rc == 1, "rc %d: %s", rc, cli_err);
    ck_assert_ptr_nonnull(strstr(cli_err, "disk"));
    pngs_whole(dir);
}
END_TEST

/* A private mount namespace for this process (and the test children it
 * forks): as root, or as root of a new user namespace.  NULL or why not. */
static const char *private_mounts(void)
{
    static char why[300];
    uid_t uid = geteuid();
    gid_t gid = getegid();
    if (unshare(CLONE_NEWNS) != 0) {
        if (unshare(CLONE_NEWUSER | CLONE_NEWNS) != 0) {
            snprintf(why, sizeof why, "no private mount namespace (unshare: %s)", strerror(errno));
            return why;
        }
        char map[64];
        int fd = open("/proc/self/setgroups", O_WRONLY);
        if (fd >= 0) {
            if (write(fd, "deny", 4) < 0) {}
            close(fd);
        }
        snprintf(map, sizeof map, "0 %u 1", (unsigned)uid);
        fd = open("/proc/self/uid_map", O_WRONLY);
        int ok = fd >= 0 && write(fd, map, strlen(map)) > 0;
        if (fd >= 0) close(fd);
        snprintf(map, sizeof map, "0 %u 1", (unsigned)gid);
        fd = open("/proc/self/gid_map", O_WRONLY);
        ok = ok && fd >= 0 && write(fd, map, strlen(map)) > 0;
        if (fd >= 0) close(fd);
        if (!ok) {
            snprintf(why, sizeof why, "cannot map the user namespace's ids");
            return why;
        }
    }
    /* nothing mounted here may reach the parent namespace */
    if (mount(NULL, "/", NULL, MS_REC | MS_PRIVATE, NULL) != 0) {
        snprintf(why, sizeof why, "cannot make the mounts private: %s", strerror(errno));
        return why;
    }
    if (mount("jf_full", disk, "tmpfs", 0, "size=1m,mode=0777") != 0) {
        snprintf(why, sizeof why, "cannot mount a tmpfs: %s", strerror(errno));
        return why;
    }
    return NULL;
}

int main(void)
{
    if (system("command -v gnuplot >/dev/null 2>&1") != 0) {
        printf("SKIP: gnuplot is not installed (Debian package gnuplot-nox)\n");
        return 77;
    }
    snprintf(disk, sizeof disk, "/tmp/jf_disk_XXXXXX");
    if (!mkdtemp(disk)) {
        perror("mkdtemp");
        return 2;
    }
    const char *why = private_mounts();
    if (why) {
        rmdir(disk);
        printf("SKIP: %s: the full-disk cases need a small tmpfs\n", why);
        return 77;
    }
    Suite *s = suite_create("cli_fulldisk");
    TCase *tc = tcase_create("fulldisk");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 180);
    tcase_add_test(tc, render_full_disk);
    tcase_add_test(tc, study_full_disk);
    tcase_add_test(tc, convergence_full_disk);
    suite_add_tcase(s, tc);
    int failures = jf_test_run(s);
    umount2(disk, MNT_DETACH);
    rmdir(disk);
    return failures;
}
