;;> \procedure{(open-multicast-socket group port interface)}
;;> A non-blocking UDP socket bound to \var{port}, a member of the IPv4
;;> multicast \var{group} on the interface with address \var{interface},
;;> whose own datagrams loop back to it.  Send and receive on it with
;;> (chibi net)'s send and receive.  The body is lib/murdoch/wire/multicast.stub
;;> and multicast-socket.c, built into lib/murdoch/wire/multicast.so by
;;> \scheme{make native}.

(define-library (murdoch wire multicast)
  (export open-multicast-socket)
  (include-shared "multicast"))
