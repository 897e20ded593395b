;;> \procedure{(hmac-sha256 key part ...)}
;;> HMAC-SHA256 under \var{key} of the message made of the \var{part}s one
;;> after the other, as a lowercase hex string.  The key and each part are
;;> a bytevector or a string (its UTF-8 bytes); a part may also be a
;;> fixnum, which stands for its decimal digits.
;;>
;;> \procedure{(hmac-sha256-sign key text parts)}
;;> \var{text} signed: a string of the MAC under \var{key} of the list
;;> \var{parts} followed by \var{text}, then \var{text}.
;;>
;;> \procedure{(hmac-sha256-write! key text parts port)}
;;> Writes to the output \var{port} the netstring of \var{text} signed as
;;> by hmac-sha256-sign, making no string of it.
;;>
;;> \procedure{(hmac-sha256-open key bytes end parts)}
;;> The text of a signed message, the first \var{end} bytes of the
;;> bytevector \var{bytes}, as a string, when its MAC is that of the list
;;> \var{parts} followed by the text; #f when it is not.
;;>
;;> The body is lib/murdoch/wire/hmac.stub and hmac-sha256.c, built into
;;> lib/murdoch/wire/hmac.so by \scheme{make native}: over Chibi's SHA-256 in
;;> Scheme a frame's MAC cost 40 us.  A frame's parts come as a list, which
;;> its caller builds once, where a rest argument would be built again.

(define-library (murdoch wire hmac)
  (export hmac-sha256 hmac-sha256-sign hmac-sha256-write! hmac-sha256-open)
  (import (scheme base))
  (include-shared "hmac")
  (begin
    (define (hmac-sha256 key . parts)
      (%hmac-sha256 key parts))))
