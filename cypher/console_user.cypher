// Create the user the dashboard's Cypher console logs in as, or give it a new password (run on the system database by the local server).
CREATE OR REPLACE USER $user SET PLAINTEXT PASSWORD $password CHANGE NOT REQUIRED
