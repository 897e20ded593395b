;;> \procedure{(open-multicast-socket group port interface)}
;;> A non-blocking UDP socket on \var{port}, a member of the IPv4 multicast
;;> \var{group} on \var{interface}, its own datagrams looping back; for
;;> (chibi net)'s send and receive.  C: multicast.stub, multicast-socket.c.

(define-library (murdoch wire multicast)
  (export open-multicast-socket)
  (include-shared "multicast"))
