/* b14-send: one-off trip requests from the command line, e.g. to press a
 * robot's button or poke at a running simulator.
 *
 *   b14-send [--host ADDR] PORT 'REQUEST' ...
 *
 * Each REQUEST is a trip request without its tag ("buttons press 2",
 * "open base", "base reckon"); they go over one connection, in order, and
 * each reply is printed on its own line.  Exit status 1 if any reply is an
 * error. */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>
#include "frame.h"

static int dial(const char *host, int port)
{
    struct sockaddr_in sa = { .sin_family = AF_INET, .sin_port = htons(port) };
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    if (inet_pton(AF_INET, host, &sa.sin_addr) != 1 || connect(fd, (struct sockaddr *)&sa, sizeof sa) < 0) {
        fprintf(stderr, "b14-send: cannot reach %s:%d\n", host, port);
        exit(2);
    }
    return fd;
}

/* The reply to request `tag`, skipping asynchronous messages. */
static int reply(int fd, frame_parser *p, int tag)
{
    char want[16];
    int n = snprintf(want, sizeof want, "%d ", tag);
    for (;;) {
        unsigned char b;
        enum frame_event ev;
        struct pollfd pfd = { fd, POLLIN, 0 };
        if (poll(&pfd, 1, 10000) <= 0 || read(fd, &b, 1) != 1) {
            fprintf(stderr, "b14-send: no reply\n");
            exit(2);
        }
        frame_feed(p, &b, 1, &ev);
        if (ev == FRAME_OK && p->len >= (size_t)n && memcmp(p->buf, want, n) == 0) {
            printf("%.*s\n", (int)(p->len - n), (const char *)p->buf + n);
            return p->len >= (size_t)n + 3 && memcmp(p->buf + n, "err", 3) == 0;
        }
    }
}

int main(int argc, char **argv)
{
    const char *host = "127.0.0.1";
    unsigned char buf[4096], out[2 * 4096 + 2], req[4096];
    frame_parser p;
    int i = 1, fd, failed = 0, tag;
    if (argc > 2 && strcmp(argv[1], "--host") == 0) {
        host = argv[2];
        i = 3;
    }
    if (i >= argc) {
        fprintf(stderr, "usage: b14-send [--host ADDR] PORT 'REQUEST' ...\n");
        return 2;
    }
    fd = dial(host, atoi(argv[i++]));
    frame_init(&p, buf, sizeof buf);
    for (tag = 1; i < argc; i++, tag++) {
        int n = snprintf((char *)req, sizeof req, "%d %s", tag, argv[i]);
        if (n < 0 || n >= (int)sizeof req)
            return 2;
        if (write(fd, out, frame_encode(req, n, out)) < 0)
            return 2;
        failed |= reply(fd, &p, tag);
    }
    close(fd);
    return failed;
}
