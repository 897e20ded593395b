;;> \procedure{(hmac-sha256 key part ...)}
;;> HMAC-SHA256 under \var{key} of the \var{part}s one after another, as
;;> lowercase hex.  Key and parts are bytevectors or strings (UTF-8); a
;;> part may be a fixnum, standing for its decimal digits.
;;> Where \var{parts} is a list below, a frame's pair (NONCE . COUNT), COUNT
;;> a fixnum, stands for the list (NONCE ":" COUNT ":").
;;> \procedure{(hmac-sha256-sign key text parts)} The MAC under \var{key}
;;> of the list \var{parts} then \var{text}, followed by \var{text}.
;;> \procedure{(hmac-sha256-write! key text parts port)} Writes the
;;> netstring of \var{text} signed, making no string of it.
;;> \procedure{(hmac-sha256-write-text! key text-port parts port max)}
;;> The same for the text written to the string port \var{text-port} since
;;> it was emptied, taken from its buffer: #t, or writing nothing, the
;;> symbol too-large past \var{max} bytes and #f when the text outgrew
;;> the buffer.
;;> \procedure{(hmac-sha256-open key bytes end parts)} The text of the
;;> signed message in the first \var{end} bytes of \var{bytes}, or #f when
;;> its MAC is not that of \var{parts} then the text.
;;> C: hmac.stub and hmac-sha256.c (docs/speed.md says why not Scheme).

(define-library (murdoch wire hmac)
  (export hmac-sha256 hmac-sha256-sign hmac-sha256-write! hmac-sha256-write-text!
          hmac-sha256-open)
  (import (scheme base))
  (include-shared "hmac")
  (begin
    (define (hmac-sha256 key . parts)
      (%hmac-sha256 key parts))))
